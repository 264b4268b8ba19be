// A board's crystal oscillator: a clock whose frequency is off by a fixed error, drifts slowly
// (a temperature ramp) and jitters from edge to edge; a voltage-controlled one (VCXO) pulled by
// the signed control word `trim` (a DAC's), TRIM_PPB parts per billion a step.
//
// Simulation only; needs Verilator's --timing. The plusargs +<PLUSARG>_<NAME>=<integer> set it:
//   PERIOD_FS  nominal period (fs), required
//   PPB        frequency error at time 0, parts per billion (positive: fast)
//   RAMP_PPB   frequency error added per millisecond of simulated time (ppb/ms)
//   JITTER_FS  each edge lands up to this far (fs) either side of its ideal time, uniformly
//   SEED       the jitter's seed (non-zero)
//   TRIM_PPB   the pull of one step of `trim` (ppb)
// The ideal edge times are summed in real arithmetic from time 0, so the simulator's 1 ps
// rounding of each delay does not accumulate: over a run the clock keeps its rate exactly.
module board_clock #(
    parameter PLUSARG = "CLK"
) (
    input  wire signed [15:0] trim,
    output reg clk
);
    integer period_fs, ppb, ramp_ppb, jitter_fs, seed, trim_ppb, pull_ppb;
    reg [31:0] noise;
    real ideal_fs, error, edge_fs, delay_ns;

    initial begin
        period_fs = 0; ppb = 0; ramp_ppb = 0; jitter_fs = 0; seed = 1;
        if (!$value$plusargs({PLUSARG, "_PERIOD_FS=%d"}, period_fs)) begin
            $display("board_clock: +%0s_PERIOD_FS missing", PLUSARG);
            $finish;
        end
        void'($value$plusargs({PLUSARG, "_PPB=%d"}, ppb));
        void'($value$plusargs({PLUSARG, "_RAMP_PPB=%d"}, ramp_ppb));
        void'($value$plusargs({PLUSARG, "_JITTER_FS=%d"}, jitter_fs));
        void'($value$plusargs({PLUSARG, "_SEED=%d"}, seed));
        trim_ppb = 0;
        void'($value$plusargs({PLUSARG, "_TRIM_PPB=%d"}, trim_ppb));
        noise = seed == 0 ? 1 : seed;
        clk = 0;
        ideal_fs = 0.0;
        forever begin
            // a fast clock (positive error) has a shorter period
            pull_ppb = $signed(trim) * trim_ppb;
            error = (ppb + ramp_ppb * (ideal_fs / 1.0e12) + pull_ppb) * 1.0e-9;
            ideal_fs = ideal_fs + period_fs / 2.0 / (1.0 + error);
            edge_fs = ideal_fs;
            // xorshift32: the same edges on every simulator and run
            noise = noise ^ (noise << 13);
            noise = noise ^ (noise >> 17);
            noise = noise ^ (noise << 5);
            if (jitter_fs > 0)
                edge_fs = edge_fs + (noise % (2 * jitter_fs + 1)) - jitter_fs;
            delay_ns = edge_fs / 1.0e6 - $realtime;
            if (delay_ns > 0.0)
                /* verilator lint_off ZERODLY */
                #(delay_ns);
                /* verilator lint_on ZERODLY */
            clk = ~clk;
        end
    end
endmodule
