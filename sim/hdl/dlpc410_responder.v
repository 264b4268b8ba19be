// The DLPC410's outputs to the applications FPGA, as sim/models/dlpc410_model.py drives them.
//
// Simulation only. The system run records the pins to a file (trace_recorder.v) and checks them
// afterwards with the Python model, so the controller's outputs must come from Verilog: this
// module follows the model's rules for INIT_ACTIVE, RST_ACTIVE and ECP2_FINISHED with the same
// cycle counts, and the offline replay compares the model's outputs with these on every recorded
// cycle. The cycle counts are inputs, so that one build serves runs with different timings (a
// constant connection costs nothing). Cycle k is the k-th rising edge of clk with `rst` low (the
// model's k-th step; the model starts after the core's reset, as trace_recorder.v does): the
// pins sampled there give the outputs of cycle k + 1.
//
// * ECP2_FINISHED from cycle ecp2_cycles on.
// * INIT_ACTIVE high while ARSTZ is low and until max(rise, ecp2_cycles) + init_cycles after
//   ARSTZ rose.
// * Past initialisation (and init_grace_cycles), DVALID high (on the cycle's first DCLK rising
//   edge) with no row cycle open starts a row cycle of CYCLES_PER_ROW cycles (DCLK per row over
//   the DCLK cycles per cycle); if BLKMD is 10 or 11 there, RST_ACTIVE is high on the next
//   rst_active_cycles cycles (plus +dlpc410_rst_extra=N cycles: a controller slower than the
//   facts table says).
// * A restart (restart_cycles > 0): INIT_ACTIVE high from cycle restart_at for restart_cycles,
//   ECP2_FINISHED low for the first restart_ecp2_cycles of them; the row cycle under way is
//   lost, and the pins are read again restart_cycles + init_grace_cycles after restart_at (the
//   model ignores the first restart_grace_cycles and checks the rest).
module dlpc410_responder #(
    parameter CYCLES_PER_ROW = 16
) (
    input  wire [31:0] rst_active_cycles,
    input  wire [31:0] init_cycles,
    input  wire [31:0] init_grace_cycles,
    input  wire [31:0] ecp2_cycles,
    input  wire [31:0] restart_at,
    input  wire [31:0] restart_cycles,
    input  wire [31:0] restart_ecp2_cycles,
    input  wire        clk,
    input  wire        rst,
    input  wire        arstz,
    input  wire        dvalid,
    input  wire [1:0]  blkmd,
    output reg         init_active,
    output reg         rst_active,
    output reg         ecp2_finished
);
    reg [63:0] cycle;
    reg [63:0] init_end;
    reg [63:0] rst_until;
    reg        arstz_seen, init_done_known, row_open;
    integer    beats;
    reg        restarting;
    integer    rst_extra;

    initial begin
        cycle = 0; init_end = 0; rst_until = 0; arstz_seen = 0; init_done_known = 0;
        row_open = 0; beats = 0; restarting = 0;
        if (!$value$plusargs("dlpc410_rst_extra=%d", rst_extra)) rst_extra = 0;
        init_active = 1; rst_active = 0; ecp2_finished = 0;
    end

    always @(posedge clk) if (!rst) begin
        if (arstz && !arstz_seen) begin
            init_end = (cycle > ecp2_cycles ? cycle : ecp2_cycles) + init_cycles;
            init_done_known = 1;
        end else if (!arstz && arstz_seen) begin
            init_done_known = 0;
            row_open = 0;
        end
        arstz_seen = arstz;
        if (restart_cycles != 0 && cycle == restart_at) row_open = 0;
        restarting = restart_cycles != 0 && cycle >= restart_at
                     && cycle < restart_at + restart_cycles + init_grace_cycles;
        if (init_done_known && cycle >= init_end + init_grace_cycles && !restarting && dvalid) begin
            if (!row_open) begin
                row_open = 1;
                beats = 0;
                if (blkmd[1] && cycle + rst_active_cycles + rst_extra > rst_until)
                    rst_until = cycle + rst_active_cycles + rst_extra;
            end
            beats = beats + 1;
            if (beats == CYCLES_PER_ROW) row_open = 0;
        end
        cycle = cycle + 1;
        ecp2_finished <= cycle >= ecp2_cycles
                         && !(restart_cycles != 0 && cycle >= restart_at && cycle < restart_at + restart_ecp2_cycles);
        init_active <= !init_done_known || cycle < init_end
                       || (restart_cycles != 0 && cycle >= restart_at && cycle < restart_at + restart_cycles);
        rst_active <= cycle <= rst_until && rst_until != 0;
    end
endmodule
