/* verilator lint_off DECLFILENAME */
// Port-only stand-ins of the two ECP5 cells board_cells.v uses, so `verilator --lint-only`
// and Icarus can read the board top with its real vendor file (they have no ECP5 library).
// Yosys uses its own cells (synth_ecp5) and never reads this file.

`default_nettype none

/* verilator lint_off UNUSEDSIGNAL */
/* verilator lint_off UNUSEDPARAM */
/* verilator lint_off UNDRIVEN */
module EHXPLLL #(
    parameter PLLRST_ENA = "DISABLED", parameter INTFB_WAKE = "DISABLED", parameter STDBY_ENABLE = "DISABLED",
    parameter DPHASE_SOURCE = "DISABLED", parameter OUTDIVIDER_MUXA = "DIVA", parameter OUTDIVIDER_MUXB = "DIVB",
    parameter OUTDIVIDER_MUXC = "DIVC", parameter OUTDIVIDER_MUXD = "DIVD", parameter CLKI_DIV = 1,
    parameter CLKOP_ENABLE = "ENABLED", parameter CLKOP_DIV = 8, parameter CLKOP_CPHASE = 0, parameter CLKOP_FPHASE = 0,
    parameter CLKOS_ENABLE = "DISABLED", parameter CLKOS_DIV = 8, parameter CLKOS_CPHASE = 0, parameter CLKOS_FPHASE = 0,
    parameter CLKOS2_ENABLE = "DISABLED", parameter CLKOS2_DIV = 8, parameter CLKOS2_CPHASE = 0, parameter CLKOS2_FPHASE = 0,
    parameter FEEDBK_PATH = "CLKOP", parameter CLKFB_DIV = 1
) (
    input wire RST, input wire STDBY, input wire CLKI, output wire CLKOP, output wire CLKOS, output wire CLKOS2,
    input wire CLKFB, input wire PHASESEL0, input wire PHASESEL1, input wire PHASEDIR,
    input wire PHASESTEP, input wire PHASELOADREG, input wire PLLWAKESYNC, input wire ENCLKOP, output wire LOCK
);
endmodule

module ODDRX1F (input wire SCLK, input wire RST, input wire D0, input wire D1, output wire Q);
endmodule
/* verilator lint_on UNDRIVEN */
/* verilator lint_on UNUSEDPARAM */
/* verilator lint_on UNUSEDSIGNAL */

`default_nettype wire
