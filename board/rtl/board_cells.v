// board_cells — the ECP5's vendor cells, and nothing else: the PLL and the four DDR outputs.
// The simulation swaps this file for board/sim/board_cells_sim.v (same module, behavioural)..
//
// EHXPLLL: 25 MHz in, VCO 625 MHz (CLKFB from CLKOP: 25 * 5 = 125, CLKOP_DIV 5), CLKOP 125 MHz
// (TMDS shift, DDR: 10 bits a pixel), CLKOS 25 MHz (pixels; 640x480 nominally wants 25.175),
// CLKOS2 625 / DRAW_DIV (the drawing clock; 16: 39.06 MHz). ODDRX1F: D0 is sent in the half
// after the rising edge, D1 after the falling edge.

`default_nettype none

module board_cells #(
    parameter DRAW_DIV = 16
) (
    input wire clk_in,
    output wire clk_pix,
    output wire clk_shift,
    output wire clk_draw,
    output wire locked,
    input wire [3:0] ddr_d0,
    input wire [3:0] ddr_d1,
    output wire [3:0] ddr_q
);

(* FREQUENCY_PIN_CLKI="25" *)
(* FREQUENCY_PIN_CLKOP="125" *)
(* FREQUENCY_PIN_CLKOS="25" *)
(* ICP_CURRENT="12" *) (* LPF_RESISTOR="8" *) (* MFG_ENABLE_FILTEROPAMP="1" *) (* MFG_GMCREF_SEL="2" *)
EHXPLLL #(
    .PLLRST_ENA("DISABLED"),
    .INTFB_WAKE("DISABLED"),
    .STDBY_ENABLE("DISABLED"),
    .DPHASE_SOURCE("DISABLED"),
    .OUTDIVIDER_MUXA("DIVA"),
    .OUTDIVIDER_MUXB("DIVB"),
    .OUTDIVIDER_MUXC("DIVC"),
    .OUTDIVIDER_MUXD("DIVD"),
    .CLKI_DIV(1),
    .CLKOP_ENABLE("ENABLED"),
    .CLKOP_DIV(5),
    .CLKOP_CPHASE(2),
    .CLKOP_FPHASE(0),
    .CLKOS_ENABLE("ENABLED"),
    .CLKOS_DIV(25),
    .CLKOS_CPHASE(2),
    .CLKOS_FPHASE(0),
    .CLKOS2_ENABLE("ENABLED"),
    .CLKOS2_DIV(DRAW_DIV),
    .CLKOS2_CPHASE(2),
    .CLKOS2_FPHASE(0),
    .FEEDBK_PATH("CLKOP"),
    .CLKFB_DIV(5)
) u_pll (
    .RST(1'b0),
    .STDBY(1'b0),
    .CLKI(clk_in),
    .CLKOP(clk_shift),
    .CLKOS(clk_pix),
    .CLKOS2(clk_draw),
    .CLKFB(clk_shift),
    .PHASESEL0(1'b0),
    .PHASESEL1(1'b0),
    .PHASEDIR(1'b1),
    .PHASESTEP(1'b1),
    .PHASELOADREG(1'b1),
    .PLLWAKESYNC(1'b0),
    .ENCLKOP(1'b0),
    .LOCK(locked)
);

genvar i;
generate
    for (i = 0; i < 4; i = i + 1) begin : ddr
        ODDRX1F u_oddr (.SCLK(clk_shift), .RST(1'b0), .D0(ddr_d0[i]), .D1(ddr_d1[i]), .Q(ddr_q[i]));
    end
endgenerate

endmodule

`default_nettype wire
