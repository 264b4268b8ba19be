// Records a bus to a text file on the cycles where something happens, with cycle stamps.
//
// Simulation only. One line "<cycle> <hex value>" for cycle 0, for every cycle where `value`
// differs from the cycle before (with ON_CHANGE; without, only the next), and for every cycle
// with `always_record` high. With STAMP_PS each line starts with the simulated time in ps:
// where a clock is not a fixed period (a board's own oscillator), that puts its events on one
// time axis with others'. The file's path is the plusarg +<PLUSARG>=<path> (a path of "-":
// nothing recorded). `flush` high writes the buffered lines out (the testbench raises it before
// it reads the file). Cycle k is the k-th rising edge of clk with `rst` low; nothing is recorded
// while `rst` is high.
module trace_recorder #(
    parameter WIDTH = 8,
    parameter PLUSARG = "TRACE",
    parameter ON_CHANGE = 1,
    parameter STAMP_PS = 0
) (
    input  wire             clk,
    input  wire             rst,
    input  wire [WIDTH-1:0] value,
    input  wire             always_record,
    input  wire             flush
);
    integer fd;
    reg [63:0] cycle;
    reg [63:0] ps;
    reg [WIDTH-1:0] last;
    reg [8*1024-1:0] path;

    initial begin
        cycle = 0;
        last = 0;
        if (!$value$plusargs({PLUSARG, "=%s"}, path))
            path = {PLUSARG, ".txt"};
        fd = path == "-" ? 0 : $fopen(path, "w");
        if (fd == 0 && path != "-") begin
            $display("trace_recorder: cannot open %0s", path);
            $finish;
        end
    end

    always @(posedge clk) begin
        if (!rst && fd != 0) begin
            if (always_record || (ON_CHANGE && (cycle == 0 || value != last))) begin
                if (STAMP_PS) begin
                    /* verilator lint_off REALCVT */
                    ps = $realtime * 1000.0;      // rounded to the nearest ps
                    /* verilator lint_on REALCVT */
                    $fwrite(fd, "%0d %0d %0h\n", ps, cycle, value);
                end else
                    $fwrite(fd, "%0d %0h\n", cycle, value);
            end
            last <= value;
            cycle <= cycle + 1;
        end
        if (flush && fd != 0)
            $fflush(fd);
    end
endmodule
