// GMII replay: plays a recorded receive stream into the design at one byte per clock.
//
// Simulation only. The fast stimulus path of the system simulation: driving GMII byte by byte
// from Python costs tens of microseconds a byte, reading a file from the simulator costs
// nanoseconds. The file (plusarg +GMII_REPLAY=<path>) holds two bytes per GMII cycle:
// flags (bit 0 = RX_DV, bit 1 = RX_ER) then RXD. Written by sim/models/gmii_stim.py.
//
// A pulse on `start` opens the file and plays it to the end; `busy` is high meanwhile.
module gmii_replay (
    input  wire       clk,
    input  wire       start,
    output reg  [7:0] rx_d,
    output reg        rx_dv,
    output reg        rx_er,
    output reg        busy
);
    integer fd;
    integer flags;
    integer data;
    reg [8*1024-1:0] path;

    initial begin
        rx_d = 8'h00;
        rx_dv = 1'b0;
        rx_er = 1'b0;
        busy = 1'b0;
        fd = 0;
        if (!$value$plusargs("GMII_REPLAY=%s", path))
            path = "gmii_replay.bin";
    end

    always @(posedge clk) begin
        if (start && !busy) begin
            fd = $fopen(path, "rb");
            if (fd == 0) begin
                $display("gmii_replay: cannot open %0s", path);
                $finish;
            end
            busy <= 1'b1;
        end else if (busy) begin
            flags = $fgetc(fd);
            data = $fgetc(fd);
            if (flags < 0 || data < 0) begin
                $fclose(fd);
                busy <= 1'b0;
                rx_dv <= 1'b0;
                rx_er <= 1'b0;
                rx_d <= 8'h00;
            end else begin
                rx_dv <= flags[0];
                rx_er <= flags[1];
                rx_d <= data[7:0];
            end
        end
    end
endmodule
