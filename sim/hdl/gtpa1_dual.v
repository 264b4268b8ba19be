// GTPA1_DUAL behavioural model: the subset gateware/platform/gtp.py uses, lane 0 only.
//
// Simulation only (needs Verilator's --timing; delays in ns, the harness's time unit), in place
// of Xilinx's unisim. Lane 0 with 8b/10b, comma alignment and clock
// correction bypassed, one byte (10 bits) a user-clock cycle, 1.25 Gb/s from a 125 MHz CLK00:
//
// * PLL: PLLLKDET0 rises SIM_LOCK_CYCLES cycles of CLK00 after GTPRESET0 falls, RESETDONE0
//   SIM_DONE_CYCLES later; both fall at once on GTPRESET0. The transmit bit clock is CLK00
//   times ten, in step with CLK00's rising edge (from CLK00's last period), so a reference
//   clock off its nominal rate gives a line off its nominal rate.
// * Transmit: on each TXUSRCLK20 rising edge the word {TXCHARDISPMODE0[0], TXCHARDISPVAL0[0],
//   TXDATA0[7:0]} is taken; at each CLK00 rising edge the serialiser sends the word taken at
//   the one before, bit 0 first (the "right-most bit first" of UG482 and UG366), ten bits a
//   word. TXN0 is ~TXP0. GTPCLKOUT0[0] is CLK00.
// * Receive: a CDR that locks to the line's edges, its nominal bit period 2 * SIM_HALF_BIT_NS
//   (0.8 ns: 1.25 Gb/s): each bit is sampled half a bit after the last edge (see the receive
//   block for its tolerance); ten bits make a word, the first in bit 0, starting SIM_RX_OFFSET
//   bits (0..9) after time 0, so words arrive at an arbitrary bit offset and the PCS must find
//   the comma. The recovered clock GTPCLKOUT0[1] rises as each word is complete, at the line's
//   rate; RXDATA0[7:0], RXCHARISK0[0] (bit 8) and RXDISPERR0[0] (bit 9) are the last complete
//   word, taken on RXUSRCLK20 (the elastic buffer, here a register).
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

    // ---- Transmit: TXUSRCLK2's word, then ten bits on the line, bit 0 first ----------------------
    // The PLL multiplies CLK00 by ten: each rising edge of CLK00 starts a word, its bits a tenth
    // of CLK00's last period apart, so the line's bit rate follows the reference clock's.
    reg [9:0] tx_word;
    reg [9:0] tx_send;
    realtime clk_edge, clk_period;
    integer tx_bit;
    initial begin
        tx_word = 10'd0;
        tx_send = 10'd0;
        TXP0 = 1'b0;
        clk_edge = 0.0;
        clk_period = 20.0 * SIM_HALF_BIT_NS;
    end
    always @(posedge TXUSRCLK20)
        tx_word <= {TXCHARDISPMODE0[0], TXCHARDISPVAL0[0], TXDATA0[7:0]};
    always @(posedge CLK00) begin
        if (clk_edge > 0.0)
            clk_period = $realtime - clk_edge;
        clk_edge = $realtime;
        // the word taken at the previous edge: the TX buffer's one word
        tx_send = tx_word;
        TXP0 = tx_send[0];
        for (tx_bit = 1; tx_bit < 10; tx_bit = tx_bit + 1) begin
            /* verilator lint_off ZERODLY */
            #(clk_period / 10.0);
            /* verilator lint_on ZERODLY */
            TXP0 = tx_send[tx_bit];
        end
    end
    assign TXN0 = ~TXP0;

    // ---- Receive: a CDR locked to the line's edges, ten bits a word; the recovered clock -------
    // Each bit is sampled half a nominal bit period (SIM_HALF_BIT_NS) after the last edge seen,
    // or a whole period after the last sample when no edge came within the last bit: the
    // sampling point follows a line whose bit rate differs from the nominal as long as the drift
    // over a run of equal bits (at most five in 8b/10b) stays under half a bit, far beyond the
    // +-100 ppm 1000BASE-X allows. Without edges the CDR free-runs at the nominal rate.
    reg [9:0] rx_shift;
    reg [9:0] rx_word;
    reg rxrecclk;
    integer rx_bit;
    realtime rx_edge, rx_next;
    initial begin
        rx_shift = 10'd0;
        rx_word = 10'd0;
        rxrecclk = 1'b0;
        rx_bit = (10 - SIM_RX_OFFSET) % 10;
        rx_edge = -1.0e9;
        RXDATA0 = 32'd0;
        RXCHARISK0 = 4'd0;
        RXDISPERR0 = 4'd0;
    end
    always @(posedge RXP0 or negedge RXP0)
        rx_edge = $realtime;
    initial begin
        rx_next = SIM_HALF_BIT_NS;
        forever begin
            /* verilator lint_off ZERODLY */
            #(rx_next - $realtime);
            /* verilator lint_on ZERODLY */
            rx_shift = {RXP0, rx_shift[9:1]};
            if (rx_bit == 9) begin
                rx_word = rx_shift;
                rxrecclk = 1'b1;
            end else if (rx_bit == 4) begin
                rxrecclk = 1'b0;
            end
            rx_bit = (rx_bit == 9) ? 0 : rx_bit + 1;
            if ($realtime - rx_edge < 2.0 * SIM_HALF_BIT_NS) begin
                rx_next = rx_edge + SIM_HALF_BIT_NS;
                while (rx_next < $realtime + SIM_HALF_BIT_NS)
                    rx_next = rx_next + 2.0 * SIM_HALF_BIT_NS;
            end else begin
                rx_next = $realtime + 2.0 * SIM_HALF_BIT_NS;
            end
        end
    end
    always @(posedge RXUSRCLK20) begin
        RXDATA0 <= {24'd0, rx_word[7:0]};
        RXCHARISK0 <= {3'd0, rx_word[8]};
        RXDISPERR0 <= {3'd0, rx_word[9]};
    end

    assign GTPCLKOUT0 = {rxrecclk, CLK00};
endmodule
