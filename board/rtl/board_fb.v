// board_fb — the board's frame buffer: P lanes of 8-bit block RAM, one lane per pixel of a block.
//
// The clock crossing: every lane is a true dual-port RAM with one port per clock. The drawing
// clock writes whole blocks (P pixels, an enable per lane); the pixel clock reads one block a
// clock and board_video picks the lane. Nothing else crosses: a pixel read while it is being
// drawn shows its old or its new value, never a mixture (one byte, one port write).
// Yosys maps each lane to ECP5 DP16KD blocks (no output register, so a read takes one clock).

`default_nettype none

module board_fb #(
    parameter P = 8,          // pixels a block
    parameter AW = 14,        // block address bits
    parameter BLOCKS = 9600   // blocks: ceil(W / P) * H
) (
    input wire wclk,
    input wire [P-1:0] we,
    input wire [AW-1:0] waddr,
    input wire [8*P-1:0] wdata,
    input wire rclk,
    input wire [AW-1:0] raddr,
    output wire [8*P-1:0] rdata
);

genvar i;
generate
    for (i = 0; i < P; i = i + 1) begin : lane
        reg [7:0] mem [0:BLOCKS-1];
        reg [7:0] q;
        always @(posedge wclk) begin
            if (we[i]) mem[waddr] <= wdata[8*i +: 8];
        end
        always @(posedge rclk) begin
            q <= mem[raddr];
        end
        assign rdata[8*i +: 8] = q;
    end
endgenerate

endmodule

`default_nettype wire
