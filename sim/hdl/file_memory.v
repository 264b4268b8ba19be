// A memory whose contents come from a file named at run time, with one asynchronous read port.
//
// Simulation only. The file (hex words, one per line, as $readmemh reads them) is the plusarg
// +<PLUSARG>=<path>; without it, or beyond the file's last word, the memory holds zeros. A
// design that takes its bulk stimulus from such memories is built once and run on any data.
module file_memory #(
    parameter WIDTH = 64,
    parameter DEPTH = 1024,
    parameter ADDR_BITS = 10,
    parameter PLUSARG = "MEMORY"
) (
    input  wire [ADDR_BITS-1:0] addr,
    output wire [WIDTH-1:0]     data
);
    reg [WIDTH-1:0] mem [0:DEPTH-1];
    reg [8*1024-1:0] path;
    integer i;

    initial begin
        for (i = 0; i < DEPTH; i = i + 1)
            mem[i] = 0;
        if ($value$plusargs({PLUSARG, "=%s"}, path))
            $readmemh(path, mem);
    end

    assign data = addr < DEPTH ? mem[addr] : {WIDTH{1'b0}};
endmodule
