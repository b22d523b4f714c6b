//! Every co-simulation suite of the harness in one test binary, so the verilated models are
//! linked once. One module per suite; run one with `cargo test -p verilator-harness --test
//! suites segment::` (or `bfpi::`, `specular::`, `render::`, `render_cli::`, `reliability::`, `cli_harness::`,
//! `frontend::`, `frontend_faults::`, `writer::`, `waveforms::`, `axis::`, `readme::`).

/// Tests `slice_0` .. `slice_7`, slice `k` calling `$run(k)`: one soaked random test cut into
/// [`verilator_harness::soak::SLICES`] tests, so nextest's partitions spread it over machines.
macro_rules! soak_slices {
    ($run:expr) => {
        const _: () = assert!(verilator_harness::soak::SLICES == 8, "soak_slices! writes one test per slice");
        #[test]
        fn slice_0() {
            ($run)(0)
        }
        #[test]
        fn slice_1() {
            ($run)(1)
        }
        #[test]
        fn slice_2() {
            ($run)(2)
        }
        #[test]
        fn slice_3() {
            ($run)(3)
        }
        #[test]
        fn slice_4() {
            ($run)(4)
        }
        #[test]
        fn slice_5() {
            ($run)(5)
        }
        #[test]
        fn slice_6() {
            ($run)(6)
        }
        #[test]
        fn slice_7() {
            ($run)(7)
        }
    };
}

mod axis;
mod bfpi;
mod cli_harness;
mod frontend;
mod frontend_faults;
mod frontend_seq;
mod ondemand;
mod readme;
mod reliability;
mod render;
mod render_cli;
mod segment;
mod specular;
mod waveforms;
mod writer;
