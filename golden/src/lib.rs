//! The golden model of segshade: the bit-exact definition of every hardware block, the
//! host-side set-up that feeds them, and f64 references that measure how close the
//! hardware comes to exact shading. See `docs/spec.md` for the contract.

pub mod bfpi;
pub mod format;
pub mod frontend;
pub mod pipeline;
pub mod raster;
pub mod rng;
pub mod rom;
pub mod schemes;
pub mod segment;
pub mod setup;
pub mod specular;
pub mod stimulus;
pub mod writer;

pub use format::{Align, Config, ConfigError, Span, SpanError};
