//! What a model is: its kind (which per-clock structs drive it), configuration, top module and
//! Verilog, and the key everything built from it is cached under.

use golden::frontend::DiMode;
use golden::pipeline::Pipeline;
use golden::setup::Screen;
use golden::Config;
use std::fmt::Write as _;
use std::hash::{Hash, Hasher};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Segment,
    Bfpi,
    Specular,
    /// `tri_frontend`: triangles in, spans out.
    Frontend,
    /// `tri_shader_p<P>`: triangles in, segments with y out.
    TriShader,
    /// `fb_writer_p<P>`: segments with y in, block writes out.
    Writer,
    /// `tri_fb_p<P>`: triangles in, block writes out.
    TriWriter,
}

impl Kind {
    /// The per-clock input and output structs of the kind's shim (the same names in
    /// csrc/shim.h and ffi.rs).
    pub fn ports(self) -> (&'static str, &'static str) {
        match self {
            Kind::Segment => ("SegIn", "SegOut"),
            Kind::Bfpi => ("BfpiIn", "BfpiOut"),
            Kind::Specular => ("SpecIn", "SpecOut"),
            Kind::Frontend => ("TriIn", "FeOut"),
            Kind::TriShader => ("TriIn", "TriSegOut"),
            Kind::Writer => ("WrIn", "WrOut"),
            Kind::TriWriter => ("TriIn", "WrOut"),
        }
    }
}

#[derive(Clone, Debug)]
pub struct Model {
    /// Symbol prefix of the shim and suffix of the Verilator class (`V<tag>`).
    pub tag: String,
    pub kind: Kind,
    pub cfg: Config,
    /// The front-end's screen (front-end models; the default elsewhere).
    pub screen: Screen,
    /// Where a front-end model's dI comes from.
    pub di: DiMode,
    pub top: String,
    /// Clocks from input transfer to first output valid (0: combinational).
    pub latency: u32,
    /// The shader's register stages (`--pipeline`).
    pub pipeline: Pipeline,
    /// Verilog sources and ROM images: (file name, text).
    pub sources: Vec<(String, String)>,
    /// `--bus axis`: the model is the AXI4-Stream wrapper `top` of the SPEC module of its kind,
    /// driven through the kind's per-clock structs, packed as this layout says.
    pub axis: Option<hdl_gen::axis::Wrapper>,
    /// The catalogue's models: the configuration they were generated from
    /// (`catalogue::options_key`), so that a model asked for with the same options is found
    /// without generating it again.
    pub options: Option<String>,
}

/// The suffix of a traced twin's tag (and symbols) after its model's.
pub const TRACED_SUFFIX: &str = "_tr";

impl Model {
    /// What the circuit is, whatever its tag: kind, top, bus and every source (in name order).
    /// Two models with the same identity are the same circuit behind the same shim, so a model
    /// asked for at run time is taken from the compiled catalogue when one there has its
    /// identity ([`Model::identity`]).
    pub fn identity_text(&self) -> String {
        let mut s = format!("{:?}\n{}\naxis {}\n", self.kind, self.top, self.axis.is_some());
        let mut sources: Vec<&(String, String)> = self.sources.iter().collect();
        sources.sort();
        for (name, text) in sources {
            write!(s, "== {name}\n{text}").expect("writing to a String");
        }
        s
    }

    /// [`Model::identity_text`]'s hash (the same in build.rs and the library: one compiler).
    pub fn identity(&self) -> u64 {
        hash(&self.identity_text())
    }
}

/// The hash cache folders are named by (`DefaultHasher`: stable for one toolchain, which is
/// all a cache under `target/` needs).
pub fn hash(text: &str) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    text.hash(&mut h);
    h.finish()
}
