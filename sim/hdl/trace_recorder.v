// Records a bus to a text file on the cycles where something happens, with cycle stamps.
//
// Simulation only. One line "<cycle> <hex value>" for cycle 0, for every cycle where `value`
// differs from the cycle before, and for every cycle with `always` high. The file's path is the
// plusarg +<PLUSARG>=<path>. `flush` high writes the buffered lines out (the testbench raises it
// before it reads the file). Cycle k is the k-th rising edge of clk with `rst` low; nothing is
// recorded while `rst` is high.
module trace_recorder #(
    parameter WIDTH = 8,
    parameter PLUSARG = "TRACE"
) (
    input  wire             clk,
    input  wire             rst,
    input  wire [WIDTH-1:0] value,
    input  wire             always_record,
    input  wire             flush
);
    integer fd;
    reg [63:0] cycle;
    reg [WIDTH-1:0] last;
    reg [8*1024-1:0] path;

    initial begin
        cycle = 0;
        last = 0;
        if (!$value$plusargs({PLUSARG, "=%s"}, path))
            path = {PLUSARG, ".txt"};
        fd = $fopen(path, "w");
        if (fd == 0) begin
            $display("trace_recorder: cannot open %0s", path);
            $finish;
        end
    end

    always @(posedge clk) begin
        if (!rst) begin
            if (cycle == 0 || value != last || always_record)
                $fwrite(fd, "%0d %0h\n", cycle, value);
            last <= value;
            cycle <= cycle + 1;
        end
        if (flush)
            $fflush(fd);
    end
endmodule
