// Spartan-6 MCB native user ports with one shared memory: the fast memory of the system run.
//
// Simulation only. The same port protocol and rules as the Python model sim/models/mcb_model.py (which
// stays the reference and the checker of the store's tests), at nanoseconds per cycle instead of
// a Python call per cycle. PORTS ports, each in its own clock and of its own width (32, 64 or 128
// bits), share one memory of WORDS 64-bit words (bytes in address order from the low bits up).
// Signals of port p are bits [p*W +: W] of the vectors below, W their width per port; the data
// and mask vectors give every port the slot of the widest port (128 data bits, 16 mask bits), a
// narrower port using the low bits of its slot.
//
// Per port: 4 commands, 64 write words and 64 read words of its width (first-word-fall-through);
// flags registered as the Python model's outputs; calib_done rises after CALIB_CYCLES of the
// port's clock; a command is taken CMD_LATENCY port cycles after it was pushed at the earliest
// (WIDTH, CALIB_CYCLES and CMD_LATENCY hold one 32-bit value per port, port 0 in the low bits).
// Byte addresses are multiples of the port's word. As in the Python model, the memory is shared
// in time (ns): a command taken by a port occupies it from when it is free for its words times
// WORD_NS (a 64-bit word) times the port's width over 64; its words move at their times (writes leave the write FIFO, reads reach the read
// FIFO READ_LATENCY_NS later), seen at the port's next clock edge. Every REFRESH_INTERVAL_NS the
// memory is busy for REFRESH_NS after the command in progress. Commands are granted in the order
// the ports' edges see them (the Python model: round robin). Times are $realtime, in ns with the
// 1 ns time unit the system build gives modules.
//
// Stalls (plusargs, none by default): +mcb_stall_permille=N makes N in 1000 commands wait a
// random time up to +mcb_stall_max_ns=T before their first word (bank conflicts, the other
// port's turn), from a xorshift generator seeded by +mcb_stall_seed=S; the memory is busy for
// everyone meanwhile. `stalls` counts them.
//
// Calibration lost (plusargs, never by default): +mcb_calib_lost_at_ns=T loses the calibration
// at time T (0: never) and regains it +mcb_calib_lost_ns=D later, once per run: calib_done is
// low from T to T + D on every port. At a port's first edge at or after T, after that edge's
// inputs, the port is reset as the MCB does: its command, write and read FIFOs, its read words
// in flight and its command under way are discarded. The first port to see it also loses the
// memory: every word becomes 64'hDEAD_0000_0000_0000 | its index, and each of its bytes is
// marked lost until written again (per byte: a masked or 32-bit write covers part of a word).
// `calib_losses` counts the losses.
//
// Rule breaks (the Python model's McbError kinds) print a message and set the port's sticky
// `fault` code: 1 before_calib (also traffic while the calibration is lost), 2 cmd_full,
// 3 misaligned, 4 out_of_range, 5 data_missing, 6 wr_full, 7 rd_empty, 8 underrun, 9 overflow,
// 10 bad_instruction, 11 read_lost (a read fetching a byte lost with the calibration).
module mcb_model #(
    parameter PORTS = 2,
    parameter WORDS = 1 << 21,
    parameter [32*PORTS-1:0] WIDTH = {32'd128, 32'd64},
    parameter [32*PORTS-1:0] CALIB_CYCLES = {32'd200, 32'd125},
    parameter [32*PORTS-1:0] CMD_LATENCY = {32'd2, 32'd2},
    parameter real WORD_NS = 5.714,
    parameter real READ_LATENCY_NS = 60.0,
    parameter real REFRESH_INTERVAL_NS = 7800.0,
    parameter real REFRESH_NS = 160.0
) (
    input  wire [PORTS-1:0]     clk,
    input  wire [PORTS-1:0]     cmd_en,
    input  wire [3*PORTS-1:0]   cmd_instr,
    input  wire [6*PORTS-1:0]   cmd_bl,
    input  wire [30*PORTS-1:0]  cmd_byte_addr,
    output wire [PORTS-1:0]     cmd_full,
    output wire [PORTS-1:0]     cmd_empty,
    input  wire [PORTS-1:0]     wr_en,
    input  wire [128*PORTS-1:0] wr_data,
    input  wire [16*PORTS-1:0]  wr_mask,
    output wire [PORTS-1:0]     wr_full,
    output wire [PORTS-1:0]     wr_empty,
    output wire [7*PORTS-1:0]   wr_count,
    output wire [PORTS-1:0]     wr_underrun,
    output wire [PORTS-1:0]     wr_error,
    input  wire [PORTS-1:0]     rd_en,
    output wire [128*PORTS-1:0] rd_data,
    output wire [PORTS-1:0]     rd_full,
    output wire [PORTS-1:0]     rd_empty,
    output wire [7*PORTS-1:0]   rd_count,
    output wire [PORTS-1:0]     rd_overflow,
    output wire [PORTS-1:0]     rd_error,
    output wire [PORTS-1:0]     calib_done,
    output wire [4*PORTS-1:0]   fault,
    output wire [31:0]          stalls,
    output wire [31:0]          calib_losses
);
    // the ports write the one memory from their own clocks (behavioural, simulation only)
    /* verilator lint_off MULTIDRIVEN */
    reg [63:0] mem [0:WORDS-1];
    // per word, one bit per byte: lost with the calibration and not written since
    reg [7:0] lost [0:WORDS-1];
    /* verilator lint_on MULTIDRIVEN */

    // when the memory is free, and when the next refresh is due (ns); shared by the ports
    /* verilator lint_off MULTIDRIVEN */
    real free_at, refresh_at;
    /* verilator lint_on MULTIDRIVEN */

    // random stalls (shared by the ports)
    integer stall_permille, stall_max_ns, stall_seed;
    /* verilator lint_off MULTIDRIVEN */
    reg [31:0] rng, stall_count;
    /* verilator lint_on MULTIDRIVEN */
    assign stalls = stall_count;

    // calibration loss (shared): when, how long, and whether the memory was lost yet
    integer lost_at_ns, lost_ns;
    /* verilator lint_off MULTIDRIVEN */
    reg [31:0] loss_count;
    /* verilator lint_on MULTIDRIVEN */
    assign calib_losses = loss_count;

    function automatic [31:0] xorshift(input [31:0] x);
        reg [31:0] y;
        begin
            y = x ^ (x << 13);
            y = y ^ (y >> 17);
            xorshift = y ^ (y << 5);
        end
    endfunction

    integer i;
    initial begin
        for (i = 0; i < WORDS; i = i + 1) begin mem[i] = 64'd0; lost[i] = 8'd0; end
        free_at = 0.0;
        refresh_at = REFRESH_INTERVAL_NS;
        if (!$value$plusargs("mcb_stall_permille=%d", stall_permille)) stall_permille = 0;
        if (!$value$plusargs("mcb_stall_max_ns=%d", stall_max_ns)) stall_max_ns = 0;
        if (!$value$plusargs("mcb_stall_seed=%d", stall_seed)) stall_seed = 1;
        rng = stall_seed == 0 ? 32'd1 : stall_seed;
        stall_count = 0;
        if (!$value$plusargs("mcb_calib_lost_at_ns=%d", lost_at_ns)) lost_at_ns = 0;
        if (!$value$plusargs("mcb_calib_lost_ns=%d", lost_ns)) lost_ns = 0;
        loss_count = 0;
    end

    genvar p;
    generate for (p = 0; p < PORTS; p = p + 1) begin : port
        localparam [31:0] CALIB = CALIB_CYCLES[32*p +: 32];
        localparam [31:0] CMD_WAIT = CMD_LATENCY[32*p +: 32];
        localparam integer W = WIDTH[32*p +: 32];
        localparam integer BYTES = W / 8;
        localparam real PORT_WORD_NS = WORD_NS * W / 64;

        // command FIFO: instr, words, byte address, cycle pushed
        reg [2:0]  c_instr [0:3];
        reg [6:0]  c_words [0:3];
        reg [31:0] c_addr  [0:3];
        reg [31:0] c_time  [0:3];
        integer c_head, c_n;
        // write FIFO: data, mask; read FIFO (port words in the low W bits of a slot's width)
        reg [127:0] w_data [0:63];
        reg [15:0]  w_mask [0:63];
        integer w_head, w_n;
        reg [127:0] r_data [0:63];
        integer r_head, r_n;
        // read words on their way: arrival cycle and data, in order
        reg [127:0] f_data [0:63];
        real       f_time [0:63];
        integer f_head, f_n;
        // the command being executed
        reg busy, writing;
        integer words_left, addr, owed;
        real now, next_word_at, refresh_end;
        reg [31:0] cycle;
        reg calib, bad_write, saw_loss;
        reg [63:0] word;
        reg read_lost;
        reg [127:0] port_word;
        integer b, j, k;
        // registered outputs
        reg o_cmd_full, o_cmd_empty, o_wr_full, o_wr_empty, o_underrun;
        reg o_rd_full, o_rd_empty, o_overflow, o_calib_done;
        reg [6:0] o_wr_count, o_rd_count;
        reg [127:0] o_rd_data;
        reg [3:0] o_fault;
        assign cmd_full[p] = o_cmd_full;
        assign cmd_empty[p] = o_cmd_empty;
        assign wr_full[p] = o_wr_full;
        assign wr_empty[p] = o_wr_empty;
        assign wr_count[7*p +: 7] = o_wr_count;
        assign wr_underrun[p] = o_underrun;
        assign wr_error[p] = o_underrun;
        assign rd_data[128*p +: 128] = o_rd_data;
        assign rd_full[p] = o_rd_full;
        assign rd_empty[p] = o_rd_empty;
        assign rd_count[7*p +: 7] = o_rd_count;
        assign rd_overflow[p] = o_overflow;
        assign rd_error[p] = o_overflow;
        assign calib_done[p] = o_calib_done;
        assign fault[4*p +: 4] = o_fault;

        initial begin
            c_head = 0; c_n = 0; w_head = 0; w_n = 0; r_head = 0; r_n = 0; f_head = 0; f_n = 0;
            busy = 0; writing = 0; words_left = 0; addr = 0; owed = 0; next_word_at = 0.0;
            cycle = 0; calib = 0; saw_loss = 0;
            o_cmd_full = 0; o_cmd_empty = 1; o_wr_full = 0; o_wr_empty = 1; o_underrun = 0;
            o_rd_full = 0; o_rd_empty = 1; o_overflow = 0; o_calib_done = 0;
            o_wr_count = 0; o_rd_count = 0; o_rd_data = 0; o_fault = 0;
        end

        task automatic break_rule(input [3:0] code, input [8*40-1:0] what);
            begin
                $display("mcb_model: port %0d: %0s (cycle %0d)", p, what, cycle);
                if (o_fault == 0) o_fault <= code;
            end
        endtask

        always @(posedge clk[p]) begin
            cycle = cycle + 1;
            now = $realtime;
            // -- the fabric side, in the Python model's order: read, command, write word
            if ((cmd_en[p] || wr_en[p] || rd_en[p]) && !calib)
                break_rule(1, "traffic while not calibrated");
            if (rd_en[p]) begin
                if (r_n == 0) break_rule(7, "rd_en while rd_empty");
                else begin r_head = (r_head + 1) % 64; r_n = r_n - 1; end
            end
            if (cmd_en[p]) begin
                if (c_n >= 4) break_rule(2, "cmd_en while cmd_full");
                else if (cmd_instr[3*p +: 3] > 3'd4) break_rule(10, "bad instruction");
                else if (cmd_instr[3*p +: 3] != 3'd4 && cmd_byte_addr[30*p +: 30] % BYTES != 0)
                    break_rule(3, "misaligned byte address");
                else if (cmd_instr[3*p +: 3] != 3'd4
                         && cmd_byte_addr[30*p +: 30] + (cmd_bl[6*p +: 6] + 1) * BYTES > WORDS * 8)
                    break_rule(4, "burst ends past the memory");
                else begin
                    bad_write = !cmd_instr[3*p] && !cmd_instr[3*p+2]
                                && (w_n - owed < cmd_bl[6*p +: 6] + 1);
                    if (bad_write) break_rule(5, "write command before its data");
                    k = (c_head + c_n) % 4;
                    c_instr[k] = cmd_instr[3*p +: 3];
                    c_words[k] = cmd_bl[6*p +: 6] + 1;
                    c_addr[k] = cmd_byte_addr[30*p +: 30];
                    c_time[k] = cycle;
                    c_n = c_n + 1;
                    if (!cmd_instr[3*p] && !cmd_instr[3*p+2]) owed = owed + cmd_bl[6*p +: 6] + 1;
                end
            end
            if (wr_en[p]) begin
                if (w_n >= 64) break_rule(6, "wr_en while wr_full");
                else begin
                    k = (w_head + w_n) % 64;
                    w_data[k] = wr_data[128*p +: 128] & ~(~128'd0 << W);
                    w_mask[k] = wr_mask[16*p +: 16] & ~(~16'd0 << BYTES);
                    w_n = w_n + 1;
                end
            end
            // -- the calibration lost: this edge's inputs go with the rest of the port's state
            if (lost_at_ns != 0 && !saw_loss && now >= lost_at_ns) begin
                saw_loss = 1;
                if (loss_count == 0) begin
                    for (j = 0; j < WORDS; j = j + 1) begin
                        mem[j] = 64'hDEAD_0000_0000_0000 | j;
                        lost[j] = 8'hFF;
                    end
                    loss_count = 1;
                end
                c_n = 0; w_n = 0; r_n = 0; f_n = 0;
                busy = 0; owed = 0;
            end
            // -- the controller side
            if (!busy && c_n != 0 && cycle >= c_time[c_head] + CMD_WAIT) begin
                // each refresh due by the start runs at its time, or once the memory is free:
                // an idle memory has done its refreshes by now (as the Python model's), they do
                // not pile up on the next command
                next_word_at = free_at > now ? free_at : now;
                while (refresh_at <= next_word_at) begin
                    refresh_end = (refresh_at > free_at ? refresh_at : free_at) + REFRESH_NS;
                    free_at = refresh_end;
                    if (next_word_at < refresh_end) next_word_at = refresh_end;
                    refresh_at = refresh_at + REFRESH_INTERVAL_NS;
                end
                if (stall_permille != 0) begin
                    rng = xorshift(rng);
                    if (rng % 1000 < stall_permille) begin
                        rng = xorshift(rng);
                        next_word_at = next_word_at + stall_max_ns * (rng % 1024) / 1024.0;
                        stall_count = stall_count + 1;
                    end
                end
                busy = c_instr[c_head] != 3'd4;
                writing = !c_instr[c_head][0];
                words_left = c_words[c_head];
                addr = c_addr[c_head];
                free_at = next_word_at + (busy ? words_left * PORT_WORD_NS : REFRESH_NS);
                next_word_at = next_word_at + PORT_WORD_NS;
                c_head = (c_head + 1) % 4;
                c_n = c_n - 1;
            end
            while (busy && next_word_at <= now) begin
                if (writing) begin
                    if (w_n == 0) begin
                        break_rule(8, "write FIFO empty during a write");
                        o_underrun <= 1'b1;
                    end else begin
                        if (W >= 64 && w_mask[w_head] == 0)
                            for (j = 0; j < W / 64; j = j + 1) begin
                                mem[addr / 8 + j] = w_data[w_head][64*j +: 64];
                                lost[addr / 8 + j] = 8'd0;
                            end
                        else
                            for (b = 0; b < BYTES; b = b + 1)
                                if (!w_mask[w_head][b]) begin
                                    word = mem[(addr + b) / 8];
                                    word[8*((addr + b) % 8) +: 8] = w_data[w_head][8*b +: 8];
                                    mem[(addr + b) / 8] = word;
                                    lost[(addr + b) / 8][(addr + b) % 8] = 1'b0;
                                end
                        w_head = (w_head + 1) % 64;
                        w_n = w_n - 1;
                        owed = owed - 1;
                    end
                end else begin
                    read_lost = 0;
                    if (W >= 64)
                        for (j = 0; j < W / 64; j = j + 1) begin
                            port_word[64*j +: 64] = mem[addr / 8 + j];
                            read_lost = read_lost || lost[addr / 8 + j] != 8'd0;
                        end
                    else begin
                        word = mem[addr / 8];
                        port_word = {96'd0, word[32*((addr / 4) % 2) +: 32]};
                        read_lost = lost[addr / 8][4*((addr / 4) % 2) +: 4] != 4'd0;
                    end
                    if (read_lost) break_rule(11, "read of a word lost with the calibration");
                    k = (f_head + f_n) % 64;
                    f_data[k] = port_word;
                    f_time[k] = next_word_at + READ_LATENCY_NS;
                    f_n = f_n + 1;
                end
                addr = addr + BYTES;
                words_left = words_left - 1;
                next_word_at = next_word_at + PORT_WORD_NS;
                if (words_left == 0) busy = 0;
            end
            while (f_n != 0 && f_time[f_head] <= now) begin
                if (r_n >= 64) begin
                    break_rule(9, "read data arrived at a full read FIFO");
                    o_overflow <= 1'b1;
                end else begin
                    r_data[(r_head + r_n) % 64] = f_data[f_head];
                    r_n = r_n + 1;
                end
                f_head = (f_head + 1) % 64;
                f_n = f_n - 1;
            end
            calib = cycle >= CALIB
                    && !(lost_at_ns != 0 && now >= lost_at_ns && now < lost_at_ns + lost_ns);
            // -- registered outputs for the next cycle
            o_cmd_full <= c_n >= 4;
            o_cmd_empty <= c_n == 0;
            o_wr_full <= w_n >= 64;
            o_wr_empty <= w_n == 0;
            o_wr_count <= w_n;
            o_rd_data <= r_n != 0 ? r_data[r_head] : 128'd0;
            o_rd_full <= r_n >= 64;
            o_rd_empty <= r_n == 0;
            o_rd_count <= r_n;
            o_calib_done <= calib;
        end
    end endgenerate
endmodule
