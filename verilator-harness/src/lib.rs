//! Co-simulation of segshade's generated RTL against the golden model, through Verilator.
//!
//! `build.rs` verilates and links the models; [`ffi`] wraps them; [`stimulus`] makes random
//! and directed triangles; [`driver`] is the clock loop every unit shares (random valid gaps
//! and backpressure, the protocol monitor, the scoreboard on a second thread); [`cosim`]
//! checks every segment of a segment shader and the final frames; [`specular`] does the same
//! for the specular unit, pixel by pixel; [`render`] draws whole scenes through them;
//! [`traffic`] makes the driver's and the sink's per-clock decisions (shared, bit for bit,
//! with the native and cocotb benches of `scripts/bench-cosim`); [`waveform`] writes FST files of
//! failures (COSIM_TRACE) and of whole runs (`--trace`).

pub mod cosim;
pub mod driver;
pub mod ffi;
pub mod frontend;
pub mod render;
pub mod report;
pub mod specular;
pub mod stimulus;
mod tape;
pub mod traffic;
pub mod waveform;
pub mod writer;

/// The seed of a random test: `COSIM_SEED` when set (to replay a failure), else a fresh one.
/// Printed either way, so every failure can be replayed.
pub fn seed(test: &str) -> u64 {
    let seed = match std::env::var("COSIM_SEED") {
        Ok(s) => s.trim().parse().unwrap_or_else(|_| panic!("COSIM_SEED='{s}' is not a whole number")),
        Err(_) => std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos() as u64 ^ (std::process::id() as u64) << 32)
            .unwrap_or(1),
    };
    eprintln!("{test}: seed {seed} (replay with COSIM_SEED={seed})");
    seed
}
