//! The `hdl-gen` command's tools beside `generate`, apart from the blocks: they use the
//! generator, no block uses them.
//!
//! - `testbench`: self-checking Icarus testbenches with golden's vectors (`hdl-gen testbench`);
//! - `wrapper`: a module between registers, for FPGA timing (`hdl-gen synth-wrapper`);
//! - `report`: the specular unit's error per n, as a table or SVG (`hdl-gen report accuracy`).

pub mod report;
pub mod testbench;
pub mod wrapper;
