// board_tb — the simulation bench of segshade_ulx3s (Verilator --binary --timing). It waits for
// led[0] (drawing done), then records the GPDI pins as a DVI receiver would: it samples every
// half shift clock, aligns words on the clock channel (its rise starts a symbol: 0000011111 sent
// LSB first), and from the next vertical sync (a control symbol with c1 = 0 on channel 0) writes
// each word of channels 0, 1, 2 as a line "c0 c1 c2" (hex) to the file +out=FILE: the rest of
// the blanking and one whole frame, with a line's margin. Exits with "board_tb: timeout" if
// drawing never ends. With +redraw it first presses F1 (btn[1]) once drawing is done and records
// after the drawing that press starts.
//
// The UART source: with +stream=FILE the bench is the host's serial port at +baud=N (default
// 3000000). Once the power-up clear is over (led[0]) it plays FILE on ftdi_txd, a line "OP V"
// (decimal) each: 0 a byte V (8N1); 1 a byte V whose stop bit is low (a framing error); 2 the
// line idle for V ns; 3 the line low for V ns; 4 F1 pressed V ns from now, for 2 us, while the
// stream goes on. It prints each byte the board sends on ftdi_rxd ("board_tb: tx HH"). When the
// stream is played and led[0] is high again, it records a frame as above, or with +writes=FILE
// it writes every frame-buffer write since the stream began ("addr we data", hex) and ends.

`timescale 1ns / 1ps
`default_nettype none

module board_tb;

localparam integer WORDS = 800 * (525 - 490) + 800 * 525 + 800;
// +timeout_ms=N: a long stream needs more than the default.
integer timeout_ms = 50;

reg clk_25mhz = 1'b0;
always #20 clk_25mhz = ~clk_25mhz;

/* verilator lint_off UNUSEDSIGNAL */
wire [7:0] led;
/* verilator lint_on UNUSEDSIGNAL */
wire [3:0] gpdi_dp;
reg [6:0] btn = 7'd0;
reg ftdi_txd = 1'b1;
wire ftdi_rxd;
segshade_ulx3s dut (.clk_25mhz(clk_25mhz), .btn(btn), .led(led), .gpdi_dp(gpdi_dp), .ftdi_txd(ftdi_txd), .ftdi_rxd(ftdi_rxd));

reg [8*1024-1:0] out_name;
integer fd;
integer words = 0;
reg [9:0] w0 = 10'd0, w1 = 10'd0, w2 = 10'd0;
reg prev_clk_lane = 1'b0;
reg armed = 1'b0;
reg recording = 1'b0;
integer drawn = 0;

initial begin
    if (!$value$plusargs("out=%s", out_name)) begin
        $display("board_tb: no +out=FILE");
        $finish;
    end
    fd = $fopen(out_name, "w");
    // In 1 ms steps: one delay of 50 ms in picoseconds overflows Verilator's 32-bit delays.
    if (!$value$plusargs("timeout_ms=%d", timeout_ms)) timeout_ms = 50;
    repeat (timeout_ms) #1000000;
    $display("board_tb: timeout: led[0] (drawing done) never rose");
    $finish;
end

// The serial port's side.
reg [8*1024-1:0] stream_name;
reg [8*1024-1:0] writes_name;
reg streaming = 1'b0;
reg logging = 1'b0;
integer baud = 3000000;
real bit_ns = 333.333;
integer sfd, wfd, op, val, got;
real reset_ns = 0.0;
event press;
reg [7:0] txb;
integer k;

task send_byte(input [7:0] b, input stop);
    integer i;
    begin
        ftdi_txd = 1'b0;
        #(bit_ns);
        for (i = 0; i < 8; i = i + 1) begin
            ftdi_txd = b[i];
            #(bit_ns);
        end
        ftdi_txd = stop;
        #(bit_ns);
        ftdi_txd = 1'b1;
    end
endtask

always @(press) begin
    #(reset_ns);
    $display("board_tb: F1 at %0t ps", $time);
    btn[1] = 1'b1;
    #2000;
    btn[1] = 1'b0;
end

initial begin
    if ($value$plusargs("stream=%s", stream_name)) begin
        if ($value$plusargs("baud=%d", baud)) bit_ns = 1.0e9 / baud;
        else bit_ns = 1.0e9 / 3000000.0;
        sfd = $fopen(stream_name, "r");
        if ($value$plusargs("writes=%s", writes_name)) begin
            wfd = $fopen(writes_name, "w");
        end else begin
            wfd = 0;
        end
        @(posedge led[0]);
        $display("board_tb: cleared at %0t ps; streaming at %0d baud", $time, baud);
        streaming = 1'b1;
        logging = wfd != 0;
        while (!$feof(sfd)) begin
            got = $fscanf(sfd, "%d %d\n", op, val);
            if (got == 2) begin
                case (op)
                    0: send_byte(val[7:0], 1'b1);
                    1: send_byte(val[7:0], 1'b0);
                    2: #(val * 1.0);
                    3: begin ftdi_txd = 1'b0; #(val * 1.0); ftdi_txd = 1'b1; end
                    4: begin reset_ns = val * 1.0; -> press; end
                    default: begin $display("board_tb: bad stream line %0d %0d", op, val); $finish; end
                endcase
            end
        end
        $display("board_tb: stream played at %0t ps", $time);
        // Long enough for the last packet to be queued (led[0] falls) and a clear to start.
        #4000;
        wait (led[0]);
        $display("board_tb: drawing done at %0t ps", $time);
        // A status record's 14 bytes, and one more.
        #(bit_ns * 150);
        if (logging) begin
            $fclose(wfd);
            $display("board_tb: writes logged at %0t ps", $time);
            $finish;
        end
        armed = 1'b1;
    end
end

always @(negedge ftdi_rxd) begin
    if (streaming) begin
        #(bit_ns * 1.5);
        for (k = 0; k < 8; k = k + 1) begin
            txb[k] = ftdi_rxd;
            #(bit_ns);
        end
        if (ftdi_rxd) $display("board_tb: tx %02x", txb);
        else $display("board_tb: tx framing error");
    end
end

always @(posedge dut.clk_draw) begin
    if (logging && |dut.fb_we) $fwrite(wfd, "%x %x %x\n", dut.fb_waddr, dut.fb_we, dut.fb_wdata);
end

// The drawing's start (after a clear), for the triangles-per-second figure.
always @(posedge dut.u_draw.drawing) $display("board_tb: drawing from %0t ps", $time);

// The ROM source: record once drawing is done (after F1's redraw with +redraw).
always @(posedge led[0]) begin
    if (!$test$plusargs("stream")) begin
        drawn = drawn + 1;
        $display("board_tb: drawing done at %0t ps", $time);
        if (drawn == 1 && $test$plusargs("redraw")) begin
            // F1 for 2 us; led[0] must fall and rise again, or the bench times out.
            $display("board_tb: pressing F1");
            btn[1] = 1'b1;
            #2000;
            btn[1] = 1'b0;
        end else begin
            armed = 1'b1;
        end
    end
end

// Half a shift period is 4 ns: sample 1 ns after each edge, away from the pins' changes.
always @(dut.u_cells.clk_shift) begin
    #1;
    if (armed && gpdi_dp[3] && !prev_clk_lane && (w0 == 10'b1101010100 || w0 == 10'b0010101011)) recording = 1'b1;
    if (recording && gpdi_dp[3] && !prev_clk_lane) begin
        $fwrite(fd, "%03x %03x %03x\n", w0, w1, w2);
        words = words + 1;
        if (words == WORDS) begin
            $fclose(fd);
            $display("board_tb: %0d words at %0t ps", words, $time);
            $finish;
        end
    end
    prev_clk_lane = gpdi_dp[3];
    w0 = {gpdi_dp[0], w0[9:1]};
    w1 = {gpdi_dp[1], w1[9:1]};
    w2 = {gpdi_dp[2], w2[9:1]};
end

endmodule

`default_nettype wire
