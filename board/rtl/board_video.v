// board_video — 640x480 at 60 Hz (800 x 525 clocks a frame, 25 MHz for 25.175) from a 320x240
// frame buffer, each pixel doubled in x and y, as DVI: TMDS on three channels (grey on all three;
// hsync and vsync, both negative, in channel 0's control symbols) and the clock channel, each
// serialized 2 bits per shift clock (5 x the pixel clock) for the DDR output cells, LSB first.
//
// Pipeline (pixel clock): counters -> RAM address -> RAM word -> lane -> TMDS symbol; the
// syncs and the active flag follow the pixel through the same stages.

`default_nettype none

module board_video #(
    parameter P = 8,     // pixels a frame-buffer block
    parameter AW = 14,   // block address bits
    parameter BPR = 40   // blocks a row: ceil(320 / P)
) (
    input wire clk_pix,
    input wire clk_shift,
    input wire locked,
    output wire [AW-1:0] fb_addr,
    input wire [8*P-1:0] fb_data,
    output wire [3:0] ddr_d0,
    output wire [3:0] ddr_d1
);

localparam LW = (P > 1) ? $clog2(P) : 1;   // lane bits (one unused bit at P = 1)

// Reset: 8 pixel clocks after lock.
reg [3:0] por;
always @(posedge clk_pix) begin
    if (!locked) por <= 4'd0;
    else if (!por[3]) por <= por + 4'd1;
end
wire rst = !por[3];

reg [9:0] hx;
reg [9:0] vy;
always @(posedge clk_pix) begin
    if (rst) begin
        hx <= 10'd0;
        vy <= 10'd0;
    end else if (hx == 10'd799) begin
        hx <= 10'd0;
        vy <= (vy == 10'd524) ? 10'd0 : vy + 10'd1;
    end else begin
        hx <= hx + 10'd1;
    end
end

// Stage 0: the frame-buffer pixel (fx, fy) and its block.
wire de0 = (hx < 10'd640) && (vy < 10'd480);
wire hs0 = !((hx >= 10'd656) && (hx < 10'd752));
wire vs0 = !((vy >= 10'd490) && (vy < 10'd492));
wire [8:0] fx = hx[9:1];
wire [8:0] fy = vy[9:1];
localparam integer LOGP = $clog2(P);
wire [8:0] bx = fx >> LOGP;
/* verilator lint_off UNUSEDSIGNAL */
wire [31:0] block = fy * BPR + {23'd0, bx};   // 32 bits: BPR is an integer; AW of them are used
/* verilator lint_on UNUSEDSIGNAL */
assign fb_addr = de0 ? block[AW-1:0] : {AW{1'b0}};
wire [LW-1:0] lane0 = (P > 1) ? fx[LW-1:0] : {LW{1'b0}};

// Stage 1: the RAM's word; stage 2: the lane's pixel.
reg de1, hs1, vs1, de2, hs2, vs2;
reg [LW-1:0] lane1;
reg [7:0] pix2;
always @(posedge clk_pix) begin
    de1 <= de0;
    hs1 <= hs0;
    vs1 <= vs0;
    lane1 <= lane0;
    de2 <= de1;
    hs2 <= hs1;
    vs2 <= vs1;
    pix2 <= fb_data[8*lane1 +: 8];
end

// Stage 3: the symbols.
wire [9:0] sym0, sym1, sym2;
tmds_encoder u_enc0 (.clk(clk_pix), .d(pix2), .de(de2), .c0(hs2), .c1(vs2), .q(sym0));
tmds_encoder u_enc1 (.clk(clk_pix), .d(pix2), .de(de2), .c0(1'b0), .c1(1'b0), .q(sym1));
tmds_encoder u_enc2 (.clk(clk_pix), .d(pix2), .de(de2), .c0(1'b0), .c1(1'b0), .q(sym2));

// Serializer (shift clock): a symbol every 5 clocks, 2 bits a clock, bit 0 first. The two
// clocks come from one PLL in phase, so the symbols are stable when loaded; the phase counter
// needs no reset (any value returns to 0..4).
reg [2:0] ph;
reg [9:0] sh0, sh1, sh2, shc;
always @(posedge clk_shift) begin
    ph <= (ph >= 3'd4) ? 3'd0 : ph + 3'd1;
    if (ph >= 3'd4) begin
        sh0 <= sym0;
        sh1 <= sym1;
        sh2 <= sym2;
        shc <= 10'b0000011111;
    end else begin
        sh0 <= {2'b00, sh0[9:2]};
        sh1 <= {2'b00, sh1[9:2]};
        sh2 <= {2'b00, sh2[9:2]};
        shc <= {2'b00, shc[9:2]};
    end
end
assign ddr_d0 = {shc[0], sh2[0], sh1[0], sh0[0]};
assign ddr_d1 = {shc[1], sh2[1], sh1[1], sh0[1]};

endmodule

`default_nettype wire
