//! Under `COSIM_RTL_DIR` the folder's circuit is the one that runs, so a model flag typed beside
//! it must describe that circuit. A flag the folder was generated otherwise is refused with one
//! line naming it and both values (exit 2), instead of being ignored by a run that then reports
//! on options it never simulated. A flag left to its default says nothing and is not compared:
//! clap's value source tells the two apart. `--p` and `--align` choose among the folder's models
//! and are refused there already ([`crate::registry`]).

use crate::models::catalogue;
use crate::models::ModelError;
use crate::registry::rtl_dir;
use hdl_gen::manifest::{Manifest, MANIFEST_FILE};

/// What the flag `id` decides in a configuration, as its manifest records it; `None` for a flag
/// that picks a model instead. An id this does not know is an error, so a new flag cannot slip by.
pub fn decided(id: &str, m: &Manifest) -> Result<Option<String>, String> {
    // The values as the flags spell them, so the refusal reads as a command line would.
    fn text<T: std::fmt::Debug>(v: &T) -> String {
        format!("{v:?}")
    }
    let fe = |f: &dyn Fn(&hdl_gen::manifest::Frontend) -> String| m.frontend.as_ref().map_or("(no front-end)".to_string(), f);
    let (pipeline, div_bits, i0, setup, span) = (
        m.parameters.pipeline.to_string(),
        fe(&|f| f.div_bits.to_string()),
        fe(&|f| f.i0.name().to_string()),
        fe(&|f| f.setup.name().to_string()),
        fe(&|f| f.span.name().to_string()),
    );
    let v = match id {
        "p" | "align" => return Ok(None),
        "frac" => m.parameters.frac.to_string(),
        "xbits" => m.parameters.xbits.to_string(),
        "prefix" => format!("'{}'", m.parameters.prefix),
        "bfpi_arch" => m.parameters.bfpi_arch.clone().unwrap_or_else(|| hdl_gen::BfpiArch::ShiftAdd.name().to_string()),
        "pipeline" => pipeline,
        "bus" => m.parameters.bus.to_string(),
        "fe_div_bits" => div_bits,
        "fe_di" => fe(&|f| f.di.name().to_string()),
        "fe_i0" => i0,
        "fe_setup" => setup,
        "fe_span" => span,
        // A target decides what it chooses: a folder generated with the same choices by flags
        // is the same circuit.
        "target" => format!("--pipeline {pipeline} --fe-div-bits {div_bits} --fe-i0 {i0} --fe-setup {setup} --fe-span {span}"),
        "brdf_k" | "max_rel_error" => {
            let g = &m.specular.geometry;
            format!("k {:?}, n ranges {}, tables {}", g.ks, text(&g.k_ranges), text(&g.tables))
        }
        other => return Err(format!("no manifest field is known for the model flag {other}")),
    };
    Ok(Some(v))
}

/// A binary's arguments parsed as `A::parse` would (exiting on a bad one), with the model flags
/// typed on the command line.
pub fn parse<A: clap::Parser>() -> (A, Vec<String>) {
    let m = A::command().get_matches();
    let args = A::from_arg_matches(&m).unwrap_or_else(|e| e.exit());
    (args, hdl_gen::cli::given_model_args(&m))
}

/// A binary's start, before it runs anything: its arguments ([`parse`]), the COSIM_RTL_DIR
/// folder read and described (one that describes no models is a usage error), and a model flag
/// the folder contradicts refused ([`refuse`]), for the options `opts` makes of the arguments
/// (`None`: a command without a model). Each failure is one `error:` line and exit status 2.
pub fn start<A: clap::Parser>(
    opts: impl FnOnce(&A) -> Option<Result<hdl_gen::Options, hdl_gen::cli::ArgsError>>,
) -> Result<A, std::process::ExitCode> {
    let (args, given) = parse::<A>();
    if let Err(e) = crate::registry::check_folder() {
        eprintln!("error: {e}");
        return Err(std::process::ExitCode::from(2));
    }
    if let Some(o) = opts(&args) {
        refuse(&given, o)?;
    }
    Ok(args)
}

/// [`check`] for a binary: the refusal as its one line, exit status 2.
pub fn refuse(given: &[String], opts: Result<hdl_gen::Options, hdl_gen::cli::ArgsError>) -> Result<(), std::process::ExitCode> {
    // Options generate refuses are the binary's own error, said where it makes them.
    let Ok(opts) = opts else { return Ok(()) };
    check(given, &opts).map_err(|e| {
        eprintln!("error: {e}");
        std::process::ExitCode::from(2)
    })
}

/// With `COSIM_RTL_DIR` set: every flag of `given` (the model flags typed on the command line,
/// `hdl_gen::cli::given_model_args`) must decide what it decided in the folder's manifest, for the
/// options `opts` the binary parsed. Without the variable, or with no such flag, nothing to check.
pub fn check(given: &[String], opts: &hdl_gen::Options) -> Result<(), ModelError> {
    let Some(dir) = rtl_dir() else { return Ok(()) };
    let given: Vec<&String> = given.iter().filter(|id| !matches!(id.as_str(), "p" | "align")).collect();
    if given.is_empty() {
        return Ok(());
    }
    let folder = catalogue::read_manifest(dir).map_err(|what| ModelError::RtlDir { dir: dir.to_path_buf(), what })?;
    let files = hdl_gen::generate(opts);
    let text = &files.iter().find(|f| f.name == MANIFEST_FILE).expect("generate writes a manifest").contents;
    let asked = Manifest::parse(text).map_err(|e| ModelError::Config(e.to_string()))?;
    for id in given {
        let (want, have) = (decided(id, &asked).map_err(ModelError::Config)?, decided(id, &folder).map_err(ModelError::Config)?);
        if want != have {
            let flag = id.replace('_', "-");
            return Err(ModelError::Config(format!(
                "--{flag}: COSIM_RTL_DIR={} was generated otherwise ({} there, {} asked); drop the flag or generate the folder with it",
                dir.display(),
                have.unwrap_or_default(),
                want.unwrap_or_default()
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn manifest(opts: &hdl_gen::Options) -> Manifest {
        let files = hdl_gen::generate(opts);
        Manifest::parse(&files.iter().find(|f| f.name == MANIFEST_FILE).unwrap().contents).unwrap()
    }

    /// Every model flag is known, and each one that changes the circuit reads differently from
    /// two manifests that differ in it (the negative control: the same manifest reads the same).
    #[test]
    fn every_model_flag_is_read_from_the_manifest() {
        let base = hdl_gen::Options::default();
        let m = manifest(&base);
        // One second generation for every flag: a generation is most of this test's time.
        let again = manifest(&base);
        for id in hdl_gen::cli::model_arg_ids() {
            assert!(decided(&id, &m).is_ok(), "{id} is not mapped to a manifest field");
            assert_eq!(decided(&id, &m), decided(&id, &again));
        }
        let pl1 = manifest(&hdl_gen::Options { pipeline: golden::pipeline::Pipeline::new(1).unwrap(), ..Default::default() });
        let div1 = manifest(&hdl_gen::Options { fe_div_bits: Some(1), ..Default::default() });
        let engine = manifest(&hdl_gen::Options { fe_setup: golden::frontend::SetupForm::Ice40Up5k, ..Default::default() });
        let cases =
            [("pipeline", &pl1), ("target", &pl1), ("fe_div_bits", &div1), ("target", &div1), ("fe_setup", &engine), ("target", &engine)];
        for (id, other) in cases {
            assert_ne!(decided(id, &m), decided(id, other), "{id}");
        }
        let span = hdl_gen::Options {
            fe_setup: golden::frontend::SetupForm::Ice40Up5k,
            fe_span: golden::frontend::SpanForm::Sequential,
            ..Default::default()
        };
        for id in ["fe_span", "target"] {
            assert_ne!(decided(id, &engine), decided(id, &manifest(&span)), "{id}");
        }
        assert!(decided("no_such_flag", &m).is_err());
    }
}
