// board_cells, behavioural (simulation only: Verilator --timing, Icarus): the PLL's three clocks
// in phase from time 0 and `locked` after 1 us; each DDR output sends D0 in the half after the
// shift clock's rising edge and D1 in the half after its falling edge, as ODDRX1F does.

`timescale 1ns / 1ps
`default_nettype none

module board_cells #(
    parameter DRAW_DIV = 16
) (
    /* verilator lint_off UNUSEDSIGNAL */
    input wire clk_in,   // the model runs its own clocks
    /* verilator lint_on UNUSEDSIGNAL */
    output reg clk_pix,
    output reg clk_shift,
    output reg clk_draw,
    output reg locked,
    input wire [3:0] ddr_d0,
    input wire [3:0] ddr_d1,
    output wire [3:0] ddr_q
);

// Half periods in ns of the 625 MHz VCO's outputs: /5, /25, /DRAW_DIV.
localparam real VCO_NS = 1.6;
initial begin
    clk_shift = 1'b0;
    forever #(VCO_NS * 5 / 2) clk_shift = ~clk_shift;
end
initial begin
    clk_pix = 1'b0;
    forever #(VCO_NS * 25 / 2) clk_pix = ~clk_pix;
end
initial begin
    clk_draw = 1'b0;
    forever #(VCO_NS * DRAW_DIV / 2) clk_draw = ~clk_draw;
end
initial begin
    locked = 1'b0;
    #1000 locked = 1'b1;
end

reg [3:0] r0;
reg [3:0] r1;
always @(posedge clk_shift) begin
    r0 <= ddr_d0;
    r1 <= ddr_d1;
end
assign ddr_q = clk_shift ? r0 : r1;

endmodule

`default_nettype wire
