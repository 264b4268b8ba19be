// Wave window: dumps the whole design while `dump` is high, once, to the file of plusarg
// +WAVE_WINDOW=<path>; nothing without the plusarg.
//
// Simulation only, for a Verilator build with tracing (--trace). Verilator ignores $dumpoff and
// $dumpon, so the dump cannot be paused: it is opened ($dumpvars, the whole model whatever its
// arguments) when `dump` rises and closed for good by wave_window_close() (wave_window.cpp) when
// it falls. Tracing starts only then, so a run of tens of milliseconds can dump a few hundred
// microseconds of every signal.
module wave_window (
    input wire dump
);
    import "DPI-C" context function void wave_window_close();

    reg [8*1024-1:0] path;
    reg named;
    reg done;

    initial begin
        named = $value$plusargs("WAVE_WINDOW=%s", path);
        done = 1'b0;
    end

    always @(posedge dump) begin
        if (named && !done) begin
            $dumpfile(path);
            $dumpvars;
        end
    end

    always @(negedge dump) begin
        if (named && !done) begin
            wave_window_close();
            done = 1'b1;
        end
    end
endmodule
