//! Co-simulation of segshade's generated RTL against the golden model, through Verilator.
//!
//! `build.rs` verilates and links the catalogue of models the suites use, and [`ondemand`] builds
//! any other configuration, a `COSIM_RTL_DIR` folder's models and every traced twin when first
//! asked for, both through one description of a model ([`models`]); [`registry`] is the run's
//! list of models, decided at run time; [`ffi`] wraps them; [`stimulus`] makes random
//! and directed triangles; [`driver`] is the clock loop every unit shares (random valid gaps
//! and backpressure, the protocol monitor, the scoreboard on a second thread); [`segment`]
//! checks every segment of a segment shader and the final frames; [`specular`] does the same
//! for the specular unit, pixel by pixel; [`render`] draws whole scenes through them;
//! [`traffic`] makes the driver's and the sink's per-clock decisions (shared, bit for bit,
//! with the native and cocotb benches of `scripts/bench-cosim`); [`waveform`] writes FST files of
//! failures (COSIM_TRACE) and of whole runs (`--trace`).

pub mod benchfile;
pub mod driver;
pub mod ffi;
pub mod frontend;
pub mod given;
// build.rs's module tree, which describes, verilates and compiles a model; the library builds
// the models asked for at run time with it (`ondemand`).
#[path = "../build/mod.rs"]
pub mod models;
pub mod ondemand;
pub mod registry;
pub mod render;
pub mod report;
pub mod segment;
pub mod soak;
pub mod specular;
pub mod stimulus;
mod tape;
pub mod targets;
pub mod traffic;
pub mod waveform;
pub mod writer;

/// The seed of a random test: `COSIM_SEED` when set (to replay a failure), else a fresh one.
/// Printed either way, so every failure can be replayed: to the test's captured output, which
/// both `cargo test` and nextest show for a failing test (and nextest's JUnit report keeps), with
/// the soak variables when they are set ([`soak`]), since they change what a seed draws.
pub fn seed(test: &str) -> u64 {
    let seed = golden::rng::env_or_clock_seed("COSIM_SEED");
    eprintln!("{test}: seed {seed} (replay with COSIM_SEED={seed}{})", soak::replay_env());
    seed
}
