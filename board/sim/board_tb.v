// board_tb — the simulation bench of segshade_ulx3s (Verilator --binary --timing). It waits for
// led[0] (drawing done), then records the GPDI pins as a DVI receiver would: it samples every
// half shift clock, aligns words on the clock channel (its rise starts a symbol: 0000011111 sent
// LSB first), and from the next vertical sync (a control symbol with c1 = 0 on channel 0) writes
// each word of channels 0, 1, 2 as a line "c0 c1 c2" (hex) to the file +out=FILE: the rest of
// the blanking and one whole frame, with a line's margin. Exits with "board_tb: timeout" if
// drawing never ends. With +redraw it first presses F1 (btn[1]) once drawing is done and records
// after the drawing that press starts.

`timescale 1ns / 1ps
`default_nettype none

module board_tb;

localparam integer WORDS = 800 * (525 - 490) + 800 * 525 + 800;
localparam integer TIMEOUT_MS = 50;

reg clk_25mhz = 1'b0;
always #20 clk_25mhz = ~clk_25mhz;

/* verilator lint_off UNUSEDSIGNAL */
wire [7:0] led;
/* verilator lint_on UNUSEDSIGNAL */
wire [3:0] gpdi_dp;
reg [6:0] btn = 7'd0;
segshade_ulx3s dut (.clk_25mhz(clk_25mhz), .btn(btn), .led(led), .gpdi_dp(gpdi_dp));

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
    repeat (TIMEOUT_MS) #1000000;
    $display("board_tb: timeout: led[0] (drawing done) never rose");
    $finish;
end

always @(posedge led[0]) begin
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
