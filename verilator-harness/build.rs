//! Compiles the catalogue of models the test suites use into the crate: generate the Verilog,
//! verilate it, compile each model at -O2 and link it statically. Any other configuration, a
//! `COSIM_RTL_DIR` folder's models and every traced twin (COSIM_TRACE, `--trace`) are built when
//! first asked for, at run time (`verilator_harness::ondemand`, `verilator_harness::registry`):
//! nothing here reads the environment the runs are configured by, so checking a folder or
//! tracing recompiles nothing. Both describe, verilate and compile a model in one way, the
//! module tree in `build/` (which the library includes too): here only the linking and the Rust
//! tables (`build/codegen.rs`) are build.rs's own.
//!
//! A model whose inputs (RTL, shim, Verilator version) are unchanged since the last build is
//! neither re-verilated nor recompiled. Models are built on as many threads as cargo gives jobs,
//! and each records its build time in `OUT_DIR/obj/<tag>/build.time` (read by the `bench` binary).

// The library uses the rest of the tree (models built at run time).
#[allow(dead_code)]
#[path = "build/mod.rs"]
mod models;

#[path = "build/codegen.rs"]
mod codegen;

use models::catalogue::{self, SpecTables};
use models::verilator::{self, cc_build, Classes, Link, Verilator};
use models::{Kind, Model};
use std::fs;
use std::path::{Path, PathBuf};
use std::time::Instant;

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=build");
    println!("cargo:rerun-if-changed=csrc/shim.h");
    println!("cargo:rerun-if-changed=csrc/trace.h");
    println!("cargo:rerun-if-env-changed=SEGSHADE_ALL_CHAINS");
    let out = PathBuf::from(std::env::var("OUT_DIR").unwrap());
    // OUT_DIR is <target>/<profile>/build/<package>-<hash>/out: the cache is one folder per
    // profile, shared by every OUT_DIR of the profile (`cargo clippy` and `cargo test` run this
    // script in OUT_DIRs of their own; the second finds the models built) and by the models the
    // library builds at run time.
    let root = out.ancestors().nth(3).map_or_else(|| out.join("cache"), |p| p.join("segshade-models"));
    println!("cargo:rustc-env=SEGSHADE_MODEL_CACHE={}", root.display());
    println!("cargo:rustc-env=SEGSHADE_TARGET={}", std::env::var("TARGET").unwrap());
    let models = catalogue::generated_models();
    let verilator = Verilator::find().unwrap_or_else(|e| panic!("\n\n{e}\n\n"));
    let globals = build_models(&verilator, &out, &root, &models);
    build_runtime(&verilator, &out, &root, &union(globals.iter()));
    println!("cargo:rustc-link-search=native={}", out.display());
    for m in &models {
        println!("cargo:rustc-link-lib=static={}", m.tag);
    }
    println!("cargo:rustc-link-lib=static={RUNTIME_LIB}");
    println!("cargo:rustc-link-lib=stdc++");
    println!("cargo:rustc-link-lib=pthread");
    println!("cargo:rustc-link-lib=atomic");
    let tables = SpecTables::of(hdl_gen::Options::default().specular_unit().plan(), None);
    fs::write(out.join("models.rs"), codegen::models_rs(&models, &tables)).unwrap();
    // The segment suite's random test is one test per (model, soak slice), so that nextest can
    // deal a configuration's soak out to several machines (`verilator_harness::soak`): its list
    // of models is the catalogue's, written where verilator-harness/tests/segment.rs includes it
    // (a COSIM_RTL_DIR folder's other shaders run in one test of their own there).
    let seg: Vec<&str> = models.iter().filter(|m| m.kind == Kind::Segment && m.axis.is_none()).map(|m| m.tag.as_str()).collect();
    fs::write(out.join("segment_slices.rs"), format!("random_triangle_slices!({});\n", seg.join(", "))).unwrap();
}

/// The runtime files the lists ask for, each once, in the order first asked.
fn union<'a>(lists: impl Iterator<Item = &'a Vec<String>>) -> Vec<String> {
    let mut all: Vec<String> = Vec::new();
    for g in lists.flatten() {
        if !all.contains(g) {
            all.push(g.clone());
        }
    }
    all
}

/// Builds every model, as many at once as cargo allows jobs (each model is one verilator run and
/// one compiler run). Returns, for each, the runtime files its makefile asks for.
fn build_models(v: &Verilator, out: &Path, root: &Path, models: &[Model]) -> Vec<Vec<String>> {
    let jobs = std::env::var("NUM_JOBS").ok().and_then(|j| j.parse().ok()).unwrap_or(1usize).clamp(1, models.len().max(1));
    let next = std::sync::atomic::AtomicUsize::new(0);
    let globals = std::sync::Mutex::new(vec![Vec::new(); models.len()]);
    std::thread::scope(|s| {
        for _ in 0..jobs {
            s.spawn(|| loop {
                let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let Some(m) = models.get(k) else { break };
                let g = build_model(v, out, root, m);
                globals.lock().unwrap()[k] = g;
            });
        }
    });
    globals.into_inner().unwrap()
}

/// Verilates and compiles one model into a static library unless its
/// key (everything the result depends on) is the one recorded by the last build. Returns the
/// runtime files its makefile asks for. (Two cargo processes building the same new key at the
/// same moment would race; scripts/test runs them one after the other.)
fn build_model(v: &Verilator, out: &Path, root: &Path, m: &Model) -> Vec<String> {
    let class = format!("V{}", m.tag);
    let key = verilator::key(v, m, false, Link::Static);
    let cache = verilator::cache_dir(root, &m.tag, &key);
    let (obj, rtl) = (cache.join("obj"), cache.join("rtl"));
    let key_file = obj.join("build.key");
    let classes_mk = obj.join(format!("{class}_classes.mk"));
    let lib = obj.join(format!("lib{}.a", m.tag));
    let fresh = fs::read_to_string(&key_file).is_ok_and(|k| k == key) && lib.exists() && classes_mk.exists();
    if !fresh {
        let start = Instant::now();
        let _ = fs::remove_dir_all(&obj);
        let _ = fs::remove_dir_all(&rtl);
        let (all, _) = verilator::verilate(m, false, &obj, &rtl, &rtl).unwrap_or_else(|e| panic!("{e}"));
        let verilated = start.elapsed().as_secs_f64();
        let mut b = cc_build(v, false, Link::Static);
        verilator::use_precompiled_header(v, &mut b, root);
        b.include(&obj).include(Path::new(env!("CARGO_MANIFEST_DIR")).join("csrc")).out_dir(&obj).file(&all);
        b.compile(&m.tag);
        let total = start.elapsed().as_secs_f64();
        fs::write(obj.join("build.time"), format!("verilate {verilated:.3}\ncompile {:.3}\ntotal {total:.3}\n", total - verilated))
            .unwrap();
        fs::write(&key_file, &key).unwrap();
    }
    let mk = Classes::read(&classes_mk).unwrap_or_else(|e| panic!("{e}"));
    // Into OUT_DIR: the library to link, and what `bench info` reads (build time, sources).
    fs::copy(&lib, out.join(format!("lib{}.a", m.tag))).unwrap();
    let (out_obj, out_rtl) = (out.join("obj").join(&m.tag), out.join("rtl").join(&m.tag));
    fs::create_dir_all(&out_obj).unwrap();
    fs::create_dir_all(&out_rtl).unwrap();
    fs::copy(obj.join("build.time"), out_obj.join("build.time")).unwrap();
    for (name, text) in &m.sources {
        fs::write(out_rtl.join(name), text).unwrap();
    }
    mk.global
}

/// Verilator's runtime library (`verilated.cpp`, `verilated_threads.cpp`, as the makefiles list
/// them), compiled once for every model.
const RUNTIME_LIB: &str = "verilated_rt";

/// Compiles `globals`, runtime files the models' makefiles ask for, into [`RUNTIME_LIB`], once
/// for every model: the cache entry the models built at run time link too
/// (`verilator::runtime_entry`), so the first shared object a test builds finds it compiled
/// instead of compiling it a second time (5 s of CPU in a cold run). Position-independent code
/// links into the executable as well; under `-fno-semantic-interposition` its calls are direct.
fn build_runtime(v: &Verilator, out: &Path, root: &Path, globals: &[String]) {
    let (key, dir, lib) = verilator::runtime_entry(v, root, globals, false);
    if !lib.exists() {
        // Built aside and renamed into place, as the library's builder expects an entry to be.
        let tmp = root.join(format!(".tmp-runtime-pic-build-{}", std::process::id()));
        let _ = fs::remove_dir_all(&tmp);
        fs::create_dir_all(&tmp).unwrap();
        let start = Instant::now();
        let mut b = cc_build(v, false, Link::Shared);
        b.out_dir(&tmp);
        for g in globals {
            b.file(v.root.join("include").join(format!("{g}.cpp")));
        }
        b.compile(verilator::RUNTIME_PIC);
        let secs = start.elapsed().as_secs_f64();
        fs::write(tmp.join("build.time"), format!("compile {secs:.3}\ntotal {secs:.3}\n")).unwrap();
        fs::write(tmp.join("build.key"), &key).unwrap();
        if fs::rename(&tmp, &dir).is_err() {
            let _ = fs::remove_dir_all(&tmp);
            assert!(lib.exists(), "{}: neither built nor found", lib.display());
        }
    }
    fs::copy(&lib, out.join(format!("lib{RUNTIME_LIB}.a"))).unwrap();
}
