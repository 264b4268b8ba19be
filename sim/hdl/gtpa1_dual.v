// GTPA1_DUAL behavioural model: the subset gateware/platform/gtp.py uses, lane 0 only.
//
// Simulation only (needs Verilator's --timing; delays in ns, the harness's time unit), in place
// of Xilinx's unisim. Lane 0 with 8b/10b, comma alignment and clock
// correction bypassed, one byte (10 bits) a user-clock cycle, 1.25 Gb/s from a 125 MHz CLK00:
//
// * PLL: PLLLKDET0 rises SIM_LOCK_CYCLES cycles of CLK00 after GTPRESET0 falls, RESETDONE0
//   SIM_DONE_CYCLES later; both fall at once on GTPRESET0. The bit clock is free-running, half
//   a period SIM_HALF_BIT_NS (0.4 ns: 1.25 Gb/s); with CLK00 at 8 ns from time 0 the two are in
//   step, as the real PLL's are.
// * Transmit: on each TXUSRCLK20 rising edge the word {TXCHARDISPMODE0[0], TXCHARDISPVAL0[0],
//   TXDATA0[7:0]} is taken; the serialiser sends the last word taken, bit 0 first, ten bits a
//   word (the TX buffer's latency is not modelled). TXN0 is ~TXP0. GTPCLKOUT0[0] is CLK00.
// * Receive: RXP0 is sampled in the middle of each bit (the bit clock's falling edge: an ideal
//   CDR for a line driven by another of these models); ten bits make a word, the first in bit 0,
//   starting SIM_RX_OFFSET bits (0..9) after time 0, so words arrive at an arbitrary bit offset
//   and the PCS must find the comma. The recovered clock GTPCLKOUT0[1] rises as each word is
//   complete; RXDATA0[7:0], RXCHARISK0[0] and RXDISPERR0[0] are the last complete word, taken on
//   RXUSRCLK20 (the elastic buffer, here a register).
// * Lane 1 and every other port: accepted and ignored; outputs not listed above read 0.
//
// Attributes are accepted (the ones gtp.py sets, lane 0) and not checked.
module GTPA1_DUAL #(
    parameter integer SIM_LOCK_CYCLES = 16,
    parameter integer SIM_DONE_CYCLES = 8,
    parameter real SIM_HALF_BIT_NS = 0.4,
    parameter integer SIM_RX_OFFSET = 3,
    parameter integer CLK25_DIVIDER_0 = 4,
    parameter integer PLL_DIVSEL_FB_0 = 5,
    parameter integer PLL_DIVSEL_REF_0 = 2,
    parameter integer PLL_TXDIVSEL_OUT_0 = 1,
    parameter integer PLL_RXDIVSEL_OUT_0 = 1,
    parameter PLL_SOURCE_0 = "PLL0",
    parameter PLL_SATA_0 = "FALSE",
    parameter [23:0] PLL_COM_CFG_0 = 24'h21680A,
    parameter [7:0] PLL_CP_CFG_0 = 8'h00,
    parameter [2:0] PLLLKDET_CFG_0 = 3'b101,
    parameter CLKINDC_B_0 = "TRUE",
    parameter CLKRCV_TRST_0 = "TRUE",
    parameter integer OOB_CLK_DIVIDER_0 = 4,
    parameter CLK_OUT_GTP_SEL_0 = "REFCLKPLL0",
    parameter [1:0] TX_TDCC_CFG_0 = 2'b00,
    parameter [19:0] PMA_TX_CFG_0 = 20'h00082,
    parameter TX_BUFFER_USE_0 = "TRUE",
    parameter TX_XCLK_SEL_0 = "TXOUT",
    parameter AC_CAP_DIS_0 = "TRUE",
    parameter [26:0] PMA_CDR_SCAN_0 = 27'h6404040,
    parameter [24:0] PMA_RX_CFG_0 = 25'h05CE048,
    parameter RCV_TERM_GND_0 = "FALSE",
    parameter RCV_TERM_VTTRX_0 = "FALSE",
    parameter TERMINATION_OVRD_0 = "FALSE",
    parameter RX_BUFFER_USE_0 = "TRUE",
    parameter RX_XCLK_SEL_0 = "RXREC",
    parameter RX_EN_IDLE_RESET_BUF_0 = "TRUE",
    parameter MCOMMA_DETECT_0 = "FALSE",
    parameter PCOMMA_DETECT_0 = "FALSE",
    parameter DEC_MCOMMA_DETECT_0 = "FALSE",
    parameter DEC_PCOMMA_DETECT_0 = "FALSE",
    parameter RX_DECODE_SEQ_MATCH_0 = "FALSE",
    parameter CLK_CORRECT_USE_0 = "FALSE",
    parameter RX_LOSS_OF_SYNC_FSM_0 = "FALSE",
    parameter PCI_EXPRESS_MODE_0 = "FALSE"
) (
    input  wire        CLK00,
    input  wire        GTPRESET0,
    input  wire        GTPRESET1,
    input  wire        PLLLKDETEN0,
    input  wire        PLLPOWERDOWN0,
    input  wire        PLLPOWERDOWN1,
    input  wire        REFCLKPWRDNB0,
    input  wire        REFCLKPWRDNB1,
    output reg         PLLLKDET0,
    output reg         RESETDONE0,
    input  wire        INTDATAWIDTH0,
    input  wire [7:0]  GTPTEST0,
    output wire [1:0]  GTPCLKOUT0,
    input  wire [2:0]  LOOPBACK0,
    input  wire [1:0]  RXPOWERDOWN0,
    input  wire [1:0]  RXPOWERDOWN1,
    input  wire [1:0]  TXPOWERDOWN0,
    input  wire [1:0]  TXPOWERDOWN1,
    input  wire        TXUSRCLK0,
    input  wire        TXUSRCLK20,
    input  wire [1:0]  TXDATAWIDTH0,
    input  wire        TXENC8B10BUSE0,
    input  wire [3:0]  TXBYPASS8B10B0,
    input  wire [3:0]  TXCHARISK0,
    input  wire [31:0] TXDATA0,
    input  wire [3:0]  TXCHARDISPVAL0,
    input  wire [3:0]  TXCHARDISPMODE0,
    input  wire        TXRESET0,
    input  wire        TXPOLARITY0,
    input  wire        TXINHIBIT0,
    input  wire        TXELECIDLE0,
    input  wire [3:0]  TXDIFFCTRL0,
    input  wire [2:0]  TXBUFDIFFCTRL0,
    input  wire [2:0]  TXPREEMPHASIS0,
    input  wire [2:0]  TXENPRBSTST0,
    output reg         TXP0,
    output wire        TXN0,
    input  wire        RXP0,
    input  wire        RXN0,
    input  wire        RXUSRCLK0,
    input  wire        RXUSRCLK20,
    input  wire [1:0]  RXDATAWIDTH0,
    input  wire        RXDEC8B10BUSE0,
    input  wire        RXCOMMADETUSE0,
    input  wire        RXENMCOMMAALIGN0,
    input  wire        RXENPCOMMAALIGN0,
    input  wire        RXSLIDE0,
    input  wire        RXRESET0,
    input  wire        RXCDRRESET0,
    input  wire        RXBUFRESET0,
    input  wire        RXPOLARITY0,
    input  wire [1:0]  RXEQMIX0,
    input  wire [2:0]  RXENPRBSTST0,
    input  wire        GATERXELECIDLE0,
    input  wire        IGNORESIGDET0,
    output reg  [31:0] RXDATA0,
    output reg  [3:0]  RXCHARISK0,
    output reg  [3:0]  RXDISPERR0
);
    // ---- PLL lock and reset done ----------------------------------------------------------
    integer count;
    initial begin
        PLLLKDET0 = 1'b0;
        RESETDONE0 = 1'b0;
        count = 0;
    end
    always @(posedge CLK00 or posedge GTPRESET0) begin
        if (GTPRESET0) begin
            PLLLKDET0 <= 1'b0;
            RESETDONE0 <= 1'b0;
            count <= 0;
        end else begin
            if (count < SIM_LOCK_CYCLES + SIM_DONE_CYCLES)
                count <= count + 1;
            PLLLKDET0 <= count >= SIM_LOCK_CYCLES;
            RESETDONE0 <= count >= SIM_LOCK_CYCLES + SIM_DONE_CYCLES;
        end
    end

    // ---- The bit clock ------------------------------------------------------------------------
    reg bitclk;
    initial bitclk = 1'b0;
    always #(SIM_HALF_BIT_NS) bitclk = ~bitclk;

    // ---- Transmit: TXUSRCLK2's word, then ten bits on the line, bit 0 first ----------------------
    reg [9:0] tx_word;
    reg [9:0] tx_shift;
    integer tx_bit;
    initial begin
        tx_word = 10'd0;
        tx_shift = 10'd0;
        tx_bit = 0;
        TXP0 = 1'b0;
    end
    always @(posedge TXUSRCLK20)
        tx_word <= {TXCHARDISPMODE0[0], TXCHARDISPVAL0[0], TXDATA0[7:0]};
    // a word starts on every tenth bit clock, in step with CLK00's rising edge
    always @(posedge bitclk) begin
        if (tx_bit == 0) begin
            TXP0 <= tx_word[0];
            tx_shift <= {1'b0, tx_word[9:1]};
        end else begin
            TXP0 <= tx_shift[0];
            tx_shift <= {1'b0, tx_shift[9:1]};
        end
        tx_bit <= (tx_bit == 9) ? 0 : tx_bit + 1;
    end
    assign TXN0 = ~TXP0;

    // ---- Receive: mid-bit samples, ten a word at SIM_RX_OFFSET; the recovered clock ------------
    reg [9:0] rx_shift;
    reg [9:0] rx_word;
    reg rxrecclk;
    integer rx_bit;
    initial begin
        rx_shift = 10'd0;
        rx_word = 10'd0;
        rxrecclk = 1'b0;
        rx_bit = (10 - SIM_RX_OFFSET) % 10;
        RXDATA0 = 32'd0;
        RXCHARISK0 = 4'd0;
        RXDISPERR0 = 4'd0;
    end
    always @(negedge bitclk) begin
        rx_shift <= {RXP0, rx_shift[9:1]};
        if (rx_bit == 9) begin
            rx_word <= {RXP0, rx_shift[9:1]};
            rxrecclk <= 1'b1;
        end else if (rx_bit == 4) begin
            rxrecclk <= 1'b0;
        end
        rx_bit <= (rx_bit == 9) ? 0 : rx_bit + 1;
    end
    always @(posedge RXUSRCLK20) begin
        RXDATA0 <= {24'd0, rx_word[7:0]};
        RXCHARISK0 <= {3'd0, rx_word[8]};
        RXDISPERR0 <= {3'd0, rx_word[9]};
    end

    assign GTPCLKOUT0 = {rxrecclk, CLK00};
endmodule
