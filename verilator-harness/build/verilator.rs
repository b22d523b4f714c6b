//! The one way a model is verilated and compiled: `verilator --cc` with the model's tag as its
//! class prefix, the file list read from the generated `*_classes.mk`, and the compiler set-up
//! Verilator's own makefile uses, at -O2 whatever the cargo profile. Each model is compiled as one
//! translation unit (its class files, then its shim), as Verilator's makefile compiles
//! `V*__ALL.cpp`: the evaluation functions inline into each other and into the shim's `step`,
//! which is what a native testbench gets.

use super::model::{hash, Kind, Model};
use super::{io, shim, ModelError};
use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;

/// How a model is linked: part of its key (a change here rebuilds the models).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Link {
    /// Into the crate (build.rs): position-independent for an executable (`-fPIE`, as g++
    /// builds a native testbench).
    Static,
    /// A shared object loaded at run time (`crate::ondemand`): `-fPIC`, with
    /// `-fno-semantic-interposition` so that GCC still inlines the model's evaluation functions
    /// into each other (under plain `-fPIC` every global function may be interposed, and is not
    /// inlined), and its own copy of Verilator's runtime, hidden inside it.
    Shared,
}

impl Link {
    /// What the key records of the link.
    pub fn layout(self) -> &'static str {
        match self {
            Link::Static => "one translation unit per model: class files, then the shim; -O2 -fPIE",
            Link::Shared => {
                "one translation unit per model: class files, then the shim; -O2 -fPIC -fno-semantic-interposition; \
                             a shared object with Verilator's runtime inside, -Wl,-Bsymbolic,--exclude-libs,ALL"
            }
        }
    }
}

/// Traced twins' difference from an untraced model's layout; part of their keys.
pub const TRACE_LAYOUT: &str = "verilator --trace-fst; -DVM_TRACE=1 -DVM_TRACE_FST=1";

/// csrc/shim.h, whose text is part of every model's key.
pub const SHIM_H: &str = include_str!("../csrc/shim.h");
/// csrc/trace.h, part of every traced twin's key.
pub const TRACE_H: &str = include_str!("../csrc/trace.h");

pub struct Verilator {
    pub root: PathBuf,
    /// `verilator --version`: part of every key.
    pub version: String,
}

impl Verilator {
    pub fn find() -> Result<Verilator, ModelError> {
        let run = |args: &[&str]| -> Result<String, ModelError> {
            let out = Command::new("verilator").args(args).output().map_err(|_| ModelError::NoVerilator)?;
            if !out.status.success() {
                return Err(ModelError::NoVerilator);
            }
            Ok(String::from_utf8_lossy(&out.stdout).trim().to_string())
        };
        let version = run(&["--version"])?;
        let root = PathBuf::from(run(&["--getenv", "VERILATOR_ROOT"])?);
        Ok(Verilator { root, version })
    }

    pub fn include(&self) -> [PathBuf; 2] {
        [self.root.join("include"), self.root.join("include/vltstd")]
    }
}

/// The compiler set-up of a model or runtime library (see [`Link`]).
///
/// `traced`: for a traced twin and the FST writer, `VM_TRACE` and `VM_TRACE_FST` are 1, as
/// Verilator's makefile sets them for a `--trace-fst` model; everything else is the same.
pub fn cc_build(v: &Verilator, traced: bool, link: Link) -> cc::Build {
    let mut b = cc::Build::new();
    b.cpp(true)
        .opt_level(2)
        .debug(false)
        .warnings(false)
        .cargo_metadata(false)
        .flag("-std=gnu++17")
        .flag("-faligned-new")
        .flag("-fcf-protection=none");
    match link {
        Link::Static => b.pic(false).flag("-fPIE"),
        Link::Shared => b.pic(true).flag("-fno-semantic-interposition"),
    };
    for d in ["VM_COVERAGE", "VM_SC", "VM_TRACE", "VM_TRACE_FST", "VM_TRACE_VCD"] {
        let on = traced && (d == "VM_TRACE" || d == "VM_TRACE_FST");
        b.define(d, if on { "1" } else { "0" });
    }
    for i in v.include() {
        b.include(i);
    }
    b
}

/// Verilator's header precompiled once per compiler set-up, under `root`, and the flags that
/// make a model's compile `b` read it: parsing `verilated.h` was two thirds of a small model's
/// compile (0.9 s of CPU against 0.3 s with it, measured on `seg_p8_span`), for some 50 models a
/// cold build. GCC checks that the precompiled header matches the compile and reads the header
/// itself when it does not, and the code is the same either way (objects compared when this
/// was written), so the precompiled header is not part of any model's key. It is built in a
/// private folder renamed into place; when it cannot be built, `b` is left as it was.
pub fn use_precompiled_header(v: &Verilator, b: &mut cc::Build, root: &Path) {
    const HEADER: &str = "segshade_pch.h";
    let Ok(tool) = b.try_get_compiler() else { return };
    let args: Vec<String> = tool.args().iter().map(|a| a.to_string_lossy().into_owned()).collect();
    // GCC checks a precompiled header's flags, not whether the header changed since: Verilator's
    // version and the header's text are part of the folder's name.
    let text = fs::read_to_string(v.root.join("include/verilated.h")).unwrap_or_default();
    let key = format!("{}\n{}\n{}\n{text}", v.version, tool.path().display(), args.join("\n"));
    let dir = root.join(format!("pch-{:016x}", hash(&key)));
    if !dir.join(format!("{HEADER}.gch")).exists() {
        static SERIAL: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let n = SERIAL.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let tmp = root.join(format!(".tmp-pch-{}-{n}", std::process::id()));
        let built = fs::create_dir_all(&tmp).is_ok()
            && fs::write(tmp.join(HEADER), "#include \"verilated.h\"\n").is_ok()
            && tool
                .to_command()
                .args(["-x", "c++-header"])
                .arg(tmp.join(HEADER))
                .arg("-o")
                .arg(tmp.join(format!("{HEADER}.gch")))
                .output()
                .is_ok_and(|o| o.status.success());
        // Another process may have put its own in place meanwhile: the same bytes; ours goes.
        if !built || fs::rename(&tmp, &dir).is_err() {
            let _ = fs::remove_dir_all(&tmp);
        }
        if !dir.join(format!("{HEADER}.gch")).exists() {
            return;
        }
    }
    b.include(&dir).flag("-include").flag(HEADER);
}

/// Everything a model's build depends on (`traced`: its traced twin): Verilator's version, the
/// layout, the top, the shims and the sources. A build is reused only under the same key.
pub fn key(v: &Verilator, m: &Model, traced: bool, link: Link) -> String {
    let class = format!("V{}", m.tag);
    let shim = shim::shim_cpp(m, &class, traced);
    let mut key = format!("{}\n{}\n{}\n{}\n{}\n", v.version, link.layout(), m.top, SHIM_H, shim);
    for (name, text) in &m.sources {
        write!(key, "== {name}\n{text}").expect("writing to a String");
    }
    if traced {
        write!(key, "== {TRACE_LAYOUT}\n{TRACE_H}").expect("writing to a String");
    }
    key
}

/// The cache entry of Verilator's runtime, the files `globals` the models' makefiles ask for:
/// its key, its folder under `root` and the archive in it. One entry for the crate's models
/// (build.rs) and the shared objects built at run time (`crate::ondemand`) alike, compiled
/// position-independent ([`Link::Shared`]'s set-up), so that it is compiled once. `traced`: the
/// FST writer's files, with `VM_TRACE` on.
pub fn runtime_entry(v: &Verilator, root: &Path, globals: &[String], traced: bool) -> (String, PathBuf, PathBuf) {
    let mut key = format!("{}\n{}\n{}\n", v.version, Link::Shared.layout(), globals.join(" "));
    if traced {
        key.push_str(TRACE_LAYOUT);
    }
    let dir = cache_dir(root, if traced { "fst-runtime-pic" } else { "runtime-pic" }, &key);
    let lib = dir.join(format!("lib{RUNTIME_PIC}.a"));
    (key, dir, lib)
}

/// The runtime archive's name (`lib<name>.a`, [`runtime_entry`]).
pub const RUNTIME_PIC: &str = "verilated_rt_pic";

/// The folder of a build with this key under `root`: `<tag>-<hash of the key>`.
pub fn cache_dir(root: &Path, tag: &str, key: &str) -> PathBuf {
    root.join(format!("{tag}-{:016x}", hash(key)))
}

/// Writes the model's sources into `rtl`, verilates them into `obj` (`traced`: with
/// `--trace-fst`), and writes the one translation unit to compile, `obj/V<tag>__all.cpp`.
/// Returns its path and the runtime files the model's makefile asks for. `images`: the absolute
/// folder the ROM images will be in when the model runs (`rtl`, or where a build made in a
/// temporary folder is renamed to).
pub fn verilate(m: &Model, traced: bool, obj: &Path, rtl: &Path, images: &Path) -> Result<(PathBuf, Vec<String>), ModelError> {
    io(obj, fs::create_dir_all(obj))?;
    io(rtl, fs::create_dir_all(rtl))?;
    let class = format!("V{}", m.tag);
    let mut files = Vec::new();
    for (name, text) in &m.sources {
        io(rtl.join(name), fs::write(rtl.join(name), text))?;
        if name.ends_with(".v") {
            files.push(rtl.join(name));
        }
    }
    // $readmemh opens its file when the model starts, from wherever the test runs: name the
    // images by absolute path.
    let image_params: Vec<String> = match m.kind {
        Kind::Specular => [("BRDF_FILE", golden::rom::BRDF_HEX), ("NK_FILE", golden::rom::NK_HEX)]
            .iter()
            .map(|(param, file)| format!("-G{param}=\"{}\"", images.join(file).display()))
            .collect(),
        _ => Vec::new(),
    };
    let out = Command::new("verilator")
        .args(["--cc", "-O3", "--x-assign", "fast", "--x-initial", "unique", "-Wno-fatal"])
        .args(traced.then_some("--trace-fst"))
        .args(["--prefix", &class, "--top-module", &m.top])
        .args(&image_params)
        .arg("-Mdir")
        .arg(obj)
        .args(&files)
        .output()
        .map_err(|_| ModelError::NoVerilator)?;
    if !out.status.success() {
        let log = String::from_utf8_lossy(&out.stderr).into_owned();
        return Err(ModelError::Verilate { top: m.top.clone(), dir: rtl.to_path_buf(), log });
    }
    let mk = Classes::read(&obj.join(format!("{class}_classes.mk")))?;
    // The model's classes and the shim in one translation unit (see the module comment).
    let mut all = String::from("// Generated by build.rs: the model and its shim, one translation unit.\n");
    for c in &mk.model {
        writeln!(all, "#include \"{c}.cpp\"").expect("writing to a String");
    }
    all.push_str(&shim::shim_cpp(m, &class, traced));
    let all_path = obj.join(format!("{class}__all.cpp"));
    io(&all_path, fs::write(&all_path, &all))?;
    Ok((all_path, mk.global))
}

/// The file lists of a `V*_classes.mk`.
pub struct Classes {
    pub model: Vec<String>,
    pub global: Vec<String>,
}

impl Classes {
    pub fn read(path: &Path) -> Result<Classes, ModelError> {
        let text = io(path, fs::read_to_string(path))?;
        let mut model = Vec::new();
        let mut global = Vec::new();
        let mut current: Option<&mut Vec<String>> = None;
        for line in text.lines() {
            let line = line.trim();
            if let Some((var, _)) = line.split_once("+=") {
                current = match var.trim() {
                    "VM_CLASSES_FAST" | "VM_CLASSES_SLOW" | "VM_SUPPORT_FAST" | "VM_SUPPORT_SLOW" => Some(&mut model),
                    "VM_GLOBAL_FAST" | "VM_GLOBAL_SLOW" => Some(&mut global),
                    _ => None,
                };
            } else if line.is_empty() || line.starts_with('#') {
                current = None;
            } else if let Some(list) = current.as_deref_mut() {
                list.extend(line.trim_end_matches('\\').split_whitespace().map(str::to_string));
            }
        }
        if model.is_empty() {
            let error = std::io::Error::new(std::io::ErrorKind::InvalidData, "lists no model files");
            return Err(ModelError::Io { path: path.to_path_buf(), error: error.into() });
        }
        Ok(Classes { model, global })
    }
}

/// Whether the compiler `b` finds zlib's header (the FST writer's); the error says which package
/// to install, rather than a compiler error deep in GTKWave's code.
pub fn require_zlib(mut b: cc::Build, obj: &Path) -> Result<(), String> {
    let probe = obj.join("zlib-probe.cpp");
    fs::write(&probe, "#include <zlib.h>\n").map_err(|e| format!("{}: {e}", probe.display()))?;
    match b.file(&probe).try_expand() {
        Ok(_) => Ok(()),
        Err(_) => Err("zlib's header (zlib.h) was not found. The traced models' FST writer needs it.\n\
             Install Debian's package:   apt-get install -y zlib1g-dev\n\
             (or run ./scripts/test, which installs it when missing)"
            .into()),
    }
}
