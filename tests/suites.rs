//! Every co-simulation suite of the harness in one test binary, so the verilated models are
//! linked once. One module per suite; run one with `cargo test -p verilator-harness --test
//! suites segment::` (or `bfpi::`, `specular::`, `render::`, `reliability::`, `cli_harness::`,
//! `frontend::`, `writer::`, `waveforms::`).

mod bfpi;
mod cli_harness;
mod frontend;
mod reliability;
mod render;
mod segment;
mod specular;
mod waveforms;
mod writer;
