//! Module names of one configuration: SPEC's names with the user's prefix.

use golden::Config;

/// Module names of one configuration, with the user's prefix applied.
#[derive(Clone, Debug)]
pub struct Names {
    pub prefix: String,
    pub bfpi: String,
    pub segment: String,
    /// SPEC §6's front-end (set-up and edge walker), and the chain of it with the shader.
    pub frontend: String,
    /// The front-end's parts, one file each: the restoring divider (parameterised: every set-up
    /// division and the per-scanline dI's) and one edge (its set-up result and its walker step).
    pub fe_div: String,
    pub fe_edge: String,
    /// The ECP5 forms' 18 x 18 product with its tile's own registers (`frontend::mul18`).
    pub fe_mul: String,
    /// The shared set-up engine (`--fe-setup` not `parallel`) and its result queue.
    pub fe_engine: String,
    pub fe_queue: String,
    pub top: String,
    /// SPEC §7's segment writer, and the chain from triangles to memory.
    pub writer: String,
    pub fb_top: String,
}

impl Names {
    pub fn new(prefix: &str, cfg: &Config) -> Names {
        Names {
            prefix: prefix.to_string(),
            bfpi: format!("{prefix}bfpi_p{}", cfg.p),
            segment: format!("{prefix}segment_shader_p{}", cfg.p),
            frontend: format!("{prefix}tri_frontend"),
            fe_div: format!("{prefix}tri_fe_div"),
            fe_edge: format!("{prefix}tri_fe_edge"),
            fe_mul: format!("{prefix}tri_fe_mul18"),
            fe_engine: format!("{prefix}tri_fe_engine"),
            fe_queue: format!("{prefix}tri_fe_queue"),
            top: format!("{prefix}tri_shader_p{}", cfg.p),
            writer: format!("{prefix}fb_writer_p{}", cfg.p),
            fb_top: format!("{prefix}tri_fb_p{}", cfg.p),
        }
    }
}

/// A module-name prefix that would not keep every name a plain Verilog identifier.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("prefix '{0}' is not a Verilog identifier start (letters, digits, '_', not starting with a digit)")]
pub struct PrefixError(pub String);

/// A module-name prefix must keep every name a plain Verilog identifier.
pub fn check_prefix(prefix: &str) -> Result<(), PrefixError> {
    let ok = prefix.chars().enumerate().all(|(k, c)| c == '_' || c.is_ascii_alphabetic() || (k > 0 && c.is_ascii_digit()));
    if ok {
        Ok(())
    } else {
        Err(PrefixError(prefix.to_string()))
    }
}
