// The Spartan-6 clock buffers the GTP wrapper (gateware/platform/gtp.py) instantiates, as
// simulation models: each passes its input through (a differential input buffer reads its
// positive leg). BUFIO2 is modelled with DIVIDE_BYPASS only (DIVCLK follows I), as the wrapper
// sets it; its other outputs read 0.
module IBUFDS (
    input  wire I,
    input  wire IB,
    output wire O
);
    assign O = I;
endmodule

module BUFIO2 #(
    parameter integer DIVIDE = 1,
    parameter DIVIDE_BYPASS = "TRUE",
    parameter I_INVERT = "FALSE",
    parameter USE_DOUBLER = "FALSE"
) (
    input  wire I,
    output wire DIVCLK,
    output wire IOCLK,
    output wire SERDESSTROBE
);
    assign DIVCLK = I;
    assign IOCLK = I;
    assign SERDESSTROBE = 1'b0;
endmodule

module BUFG (
    input  wire I,
    output wire O
);
    assign O = I;
endmodule
