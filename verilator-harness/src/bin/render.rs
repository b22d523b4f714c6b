//! `render`: draws a scene (`--scene sphere|torus`) or a triangle file (`--triangles FILE`)
//! through the verilated RTL, writes it as a PNG, renders the same input with the golden model
//! and exits non-zero when the two images differ in any pixel.
//!
//! Exit status: 0 the RTL image equals golden's; 1 it does not (or a co-simulation check
//! failed), the images are written anyway; 2 bad arguments or input (one `error: ...` message,
//! nothing written).

use clap::{ArgGroup, Parser, ValueEnum};
use golden::setup::Screen;
use hdl_gen::cli::ModelArgs;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;
use verilator_harness::ffi::ModelInfo;
use verilator_harness::models::ModelError;
use verilator_harness::ondemand;
use verilator_harness::render::{busy_cycles, difference_image, obj_job, run_with, scene_job, triangles_job, Chain, Job, SceneKind};
use verilator_harness::waveform::trace_everything;

#[derive(Parser)]
#[command(about = "Render a scene or a triangle file through the generated RTL to PNG, checked against golden")]
#[command(group(ArgGroup::new("input").required(true).args(["scene", "triangles", "obj"])))]
struct Args {
    /// Who sets up the triangles: `host` (golden::setup, spans into segment_shader_p<P>) or `rtl`
    /// (the generated front-end and shader, tri_shader_p<P>); the image must then equal golden's
    /// front-end image, and how it differs from the host-set-up image is printed.
    #[arg(long, value_enum, default_value_t = Frontend::Host)]
    frontend: Frontend,
    /// Where the shaded segments land: `host` (the harness paints them into the image) or `rtl`
    /// (SPEC §7's fb_writer_p<P> writes them into a block-memory model, the image is read out
    /// of memory; with --frontend rtl the whole chain tri_fb_p<P>, triangles to memory).
    #[arg(long, value_enum, default_value_t = Writer::Host)]
    writer: Writer,
    /// A built-in scene: a lit RGB object, Gouraud diffuse through one segment shader per
    /// channel plus the specular unit's highlight.
    #[arg(long, value_enum)]
    scene: Option<SceneKind>,
    /// A triangle file (SPEC §5: `x0 y0 i0 x1 y1 i1 x2 y2 i2` per line, `#` comments): 8-bit
    /// grayscale, background 0, later triangles over earlier ones, diffuse only. Input files
    /// (this and --obj) hold at most 64 MiB, in lines of at most 4096 bytes.
    #[arg(long, value_name = "FILE")]
    triangles: Option<PathBuf>,
    /// A Wavefront OBJ mesh (polygons triangulated; normals from the file, else smoothed from
    /// the faces), scaled to fill the view and lit like the scenes.
    #[arg(long, value_name = "FILE.obj")]
    obj: Option<PathBuf>,
    // The models to run: any configuration `generate` accepts, by the same flags (the compiled
    // catalogue's when it has them, else built the first time, then cached).
    #[command(flatten)]
    model: ModelArgs,
    /// Image width (1..=32768; see --height).
    #[arg(long, default_value_t = 640, value_parser = clap::value_parser!(u32).range(1..=MAX_SIDE))]
    width: u32,
    /// Image height (1..=32768: a scene or mesh is framed to the image, and a triangle file's
    /// vertices stop at golden::setup::COORD_LIMIT, so no triangle reaches past it).
    #[arg(long, default_value_t = 480, value_parser = clap::value_parser!(u32).range(1..=MAX_SIDE))]
    height: u32,
    /// Blinn–Phong exponent n of the scene's highlight.
    #[arg(long, default_value_t = 40, value_parser = clap::value_parser!(u16).range(1..=1000), conflicts_with = "triangles")]
    shininess: u16,
    /// The RTL image. Golden's goes next to it as `<stem>.golden.png` (stem: the name without
    /// `.png`), the difference image, with --diff, as `<stem>.diff.png`.
    #[arg(long, value_name = "FILE.png")]
    out: PathBuf,
    /// Also write the difference image: matching pixels dim gray, differing ones red.
    #[arg(long)]
    diff: bool,
    /// No progress line.
    #[arg(long)]
    quiet: bool,
    /// Write every clock of every model instance into FST files in DIR (`<model>-seed<seed>.fst`),
    /// for GTKWave or Surfer. For small renders (try --width 64 --height 48): tens of bytes per
    /// clock (45 for seg_p8_span, docs/regressions.md). The models' traced twins are
    /// built first, the first time (seconds each), then cached.
    #[arg(long, value_name = "DIR")]
    trace: Option<PathBuf>,
}

/// Widest and tallest image: a scene or mesh is framed to the image, so its vertices reach its
/// far edges, and the set-up refuses a coordinate beyond `COORD_LIMIT` (a taller image made a late
/// error, or gigabytes of buffers first).
const MAX_SIDE: i64 = golden::setup::COORD_LIMIT as i64;

/// The text of an input file (`hdl_gen::input`: refused when it is a folder, over 64 MiB, not
/// UTF-8 or with a line over 4096 bytes).
fn read_input(file: &Path) -> Result<String, String> {
    hdl_gen::input::read_text(file).map_err(|e| e.to_string())
}

/// What can be checked before any model is chosen: every output writable and none of them the
/// input file, so a bad --out costs no rendering and never destroys what it was made from.
fn check_args(args: &Args) -> Result<(), String> {
    let input = args.triangles.as_deref().or(args.obj.as_deref());
    let mut outs = vec![args.out.clone(), sibling(&args.out, ".golden.png")];
    if args.diff {
        outs.push(sibling(&args.out, ".diff.png"));
    }
    for out in &outs {
        hdl_gen::output::check_writable(out).map_err(|e| format!("--out: {e}"))?;
        if let Some(input) = input {
            hdl_gen::output::check_not_input(out, &[input]).map_err(|e| format!("--out: {e}"))?;
        }
    }
    Ok(())
}

fn fail(msg: impl std::fmt::Display) -> ExitCode {
    eprintln!("error: {msg}");
    ExitCode::from(2)
}

/// `<stem><suffix>` next to `out`, the stem being `out` without a final `.png`.
fn sibling(out: &Path, suffix: &str) -> PathBuf {
    let s = out.as_os_str().to_string_lossy();
    let stem = s.strip_suffix(".png").unwrap_or(&s);
    PathBuf::from(format!("{stem}{suffix}"))
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Frontend {
    Host,
    Rtl,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Writer {
    Host,
    Rtl,
}

/// The model `found` for `screen` (the catalogue's or one built for this configuration, see
/// `ondemand`), or the one-line reason there is none and the exit status.
fn model_for<I, O>(
    found: Result<&'static ModelInfo<I, O>, ModelError>,
    screen: Screen,
    what: &str,
) -> Result<&'static ModelInfo<I, O>, (String, u8)> {
    match found {
        Ok(m) if m.screen == screen => Ok(m),
        Ok(m) => Err((
            format!("{what}: the model {} draws on {}x{}, not {}x{}", m.tag, m.screen.width, m.screen.height, screen.width, screen.height),
            2,
        )),
        Err(e) => Err((format!("{what}: {e}"), ondemand::exit_status(&e))),
    }
}

fn main() -> ExitCode {
    // A COSIM_RTL_DIR folder that describes no models, or that a model flag contradicts, is
    // refused before anything runs.
    let args = match verilator_harness::given::start::<Args>(|a| Some(a.model.options(None))) {
        Ok(args) => args,
        Err(code) => return code,
    };
    if let Err(e) = check_args(&args) {
        return fail(e);
    }
    let start = Instant::now();
    let (p, align) = (args.model.seg.p, args.model.seg.align);
    let opts = match args.model.options(None) {
        Ok(opts) => opts,
        Err(e) => return fail(e.to_string()),
    };
    let info = match verilator_harness::registry::segment(&opts) {
        Ok(info) => info,
        Err(e) => return ondemand::exit(&format!("--p {p} --align {align}"), &e),
    };
    let screen = Screen { width: args.width, height: args.height };
    if let Err(e) = screen.check_for(&info.cfg) {
        return fail(format!("--width/--height: {e}"));
    }
    // The RTL blocks on this screen: the catalogue's, or built for it.
    let on_screen = || args.model.options(Some(screen)).map_err(|e| ModelError::Config(e.to_string()));
    let chain = match (args.frontend, args.writer) {
        (Frontend::Host, Writer::Host) => Ok(Chain::Host),
        (Frontend::Host, Writer::Rtl) => {
            model_for(on_screen().and_then(|o| verilator_harness::registry::writer(&o)), screen, "--writer rtl").map(Chain::HostToMemory)
        }
        (Frontend::Rtl, Writer::Host) => {
            model_for(on_screen().and_then(|o| verilator_harness::registry::tri_shader(&o)), screen, "--frontend rtl").map(Chain::Rtl)
        }
        (Frontend::Rtl, Writer::Rtl) => {
            model_for(on_screen().and_then(|o| verilator_harness::registry::tri_writer(&o)), screen, "--frontend rtl --writer rtl")
                .map(Chain::RtlToMemory)
        }
    };
    let chain = match chain {
        Ok(c) => c,
        Err((e, status)) => {
            eprintln!("error: {e}");
            return ExitCode::from(status);
        }
    };
    let golden_path = sibling(&args.out, ".golden.png");
    let diff_path = sibling(&args.out, ".diff.png");

    let job = match (&args.scene, &args.triangles, &args.obj) {
        (Some(kind), _, _) => scene_job(*kind, args.shininess, &info.cfg, &screen).map_err(|e| format!("--scene {}: {e}", kind.name())),
        (None, Some(file), _) => {
            read_input(file).and_then(|t| triangles_job(&t, &info.cfg, &screen).map_err(|e| format!("{}: {e}", file.display())))
        }
        (None, None, Some(file)) => {
            read_input(file).and_then(|t| obj_job(&t, args.shininess, &info.cfg, &screen).map_err(|e| format!("{}: {e}", file.display())))
        }
        (None, None, None) => unreachable!("clap requires one"),
    };
    let job = match job {
        Ok(j) => j,
        Err(e) => return fail(e),
    };
    // A scene's or mesh's highlight: the specular unit of the same options.
    let spec = match args.scene.is_some() || args.obj.is_some() {
        false => None,
        true => match verilator_harness::registry::specular(&opts) {
            Ok(info) => Some(info),
            Err(e) => return ondemand::exit("--scene/--obj: the specular unit", &e),
        },
    };
    if let Some(trace) = &args.trace {
        // The models this run builds instances of must have traced twins.
        let mut need = match chain {
            Chain::Host => vec![ondemand::require_traced(info)],
            Chain::HostToMemory(w) => vec![ondemand::require_traced(info), ondemand::require_traced(w)],
            Chain::Rtl(m) => vec![ondemand::require_traced(m)],
            Chain::RtlToMemory(m) => vec![ondemand::require_traced(m)],
        };
        if args.scene.is_some() || args.obj.is_some() {
            need.extend(spec.map(ondemand::require_traced));
        }
        if let Err(e) = need.into_iter().collect::<Result<Vec<()>, _>>().and_then(|_| trace_everything(trace)) {
            return fail(format!("--trace: {e}"));
        }
    }

    // indicatif hides the bar by itself when stderr is not a terminal.
    let bar = match args.quiet {
        true => indicatif::ProgressBar::hidden(),
        false => indicatif::ProgressBar::new(1000)
            .with_style(indicatif::ProgressStyle::with_template("rendering [{bar:40}] {percent:>3}%").expect("a valid template")),
    };
    let outcome = run_with(&job, info, chain, spec, |f| bar.set_position((f * 1000.0) as u64));
    bar.finish_and_clear();

    let channels = job.channels();
    let color = if channels == 3 { png::ColorType::Rgb } else { png::ColorType::Grayscale };
    let mut files =
        vec![(args.out.clone(), png(&outcome.rtl, &screen, color)), (golden_path.clone(), png(&outcome.golden, &screen, color))];
    if args.diff {
        let d = difference_image(&outcome.rtl, &outcome.golden, channels);
        files.push((diff_path.clone(), png(&d, &screen, png::ColorType::Rgb)));
    }
    let staged: Vec<(PathBuf, &[u8])> = files.iter().map(|(p, b)| (p.clone(), b.as_slice())).collect();
    if let Err(e) = hdl_gen::output::write_files(&staged) {
        return fail(e);
    }
    let secs = start.elapsed().as_secs_f64();

    let differing = outcome.differing_pixels(channels);
    summary(&args, &job, &outcome, info.tag, chain, secs);
    for path in files.iter().map(|(p, _)| p.clone()).chain(verilator_harness::waveform::written()) {
        println!("wrote       {}", path.display());
    }
    for r in outcome.segment.iter().chain(&outcome.writer).chain(&outcome.specular) {
        for m in &r.mismatches {
            println!("MISMATCH {m}");
        }
    }
    if let Some(host) = &outcome.host {
        let n = (0..host.len() / channels)
            .filter(|&k| host[k * channels..(k + 1) * channels] != outcome.rtl[k * channels..(k + 1) * channels])
            .count();
        let tag = match chain {
            Chain::Rtl(m) => m.tag,
            Chain::RtlToMemory(m) => m.tag,
            _ => "",
        };
        println!("front-end:  {tag} (RTL set-up); differs from the host-set-up image in {n} pixels");
        if n > 0 {
            println!("            (vertex intensities are rounded onto the UQ8.F ports; the host interpolates the exact ones)");
        }
    }
    if differing == 0 && outcome.cosim_ok() {
        println!("RTL image matches golden in every pixel");
        ExitCode::SUCCESS
    } else {
        println!("RTL image differs from golden in {differing} pixels");
        ExitCode::from(1)
    }
}

fn summary(args: &Args, job: &Job, o: &verilator_harness::render::Outcome, tag: &str, chain: Chain, secs: f64) {
    let what = match (&args.scene, &args.triangles, &args.obj) {
        (Some(s), _, _) => format!("scene {}", s.name()),
        (_, Some(f), _) => format!("triangles {}", f.display()),
        (_, _, Some(f)) => format!("mesh {}", f.display()),
        _ => String::new(),
    };
    // The models that ran: with the RTL front-end the segment shader inside the chain is the
    // chain's, so naming the spans-fed shader model (`tag`) there would name one that never ran.
    let models = match chain {
        Chain::Host => tag.to_string(),
        Chain::HostToMemory(w) => format!("{tag} + {}", w.tag),
        Chain::Rtl(m) => m.tag.to_string(),
        Chain::RtlToMemory(m) => m.tag.to_string(),
    };
    println!("render {what}, {}x{}, model {models} x {} channel(s)", job.screen.width, job.screen.height, job.channels());
    if job.drawn == job.triangles {
        println!("triangles:  {}", job.triangles);
    } else {
        println!("triangles:  {} ({} after back-face culling)", job.triangles, job.drawn);
    }
    let seg = &o.segment[0];
    let cycles = busy_cycles(seg);
    println!("spans:      {}", job.spans());
    let (unit, outputs) = match chain {
        Chain::RtlToMemory(_) => ("the chain to memory", "block writes"),
        _ => ("segment shader", "segments"),
    };
    println!("{:<11} {} per channel", format!("{outputs}:"), seg.segments);
    println!("pixels:     {} shaded per channel, {} visible", seg.pixels, job.visible_pixels());
    println!("RTL clocks: {cycles} ({unit}, each channel's instance)");
    if let Some(w) = o.writer.first() {
        println!(
            "writer:     {} block writes in {} clocks per channel (fb_writer_p{}, memory model)",
            w.segments,
            busy_cycles(w),
            args.model.seg.p
        );
    }
    println!("pixels per clock: {:.3}", seg.pixels as f64 / cycles.max(1) as f64);
    if let Some(s) = &o.specular {
        println!("specular unit: {} pixels in {} clocks (one pixel per clock)", s.pixels, busy_cycles(s));
    }
    println!("wall time:  {secs:.2} s");
}

fn png(buf: &[u8], screen: &Screen, color: png::ColorType) -> Vec<u8> {
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, screen.width, screen.height);
    encoder.set_color(color);
    encoder.set_depth(png::BitDepth::Eight);
    // Stated, not left to the crate's defaults: the committed docs/*.png are compared byte for
    // byte with what their commands write (verilator-harness/tests/readme.rs). No tIME or text chunk is written.
    encoder.set_compression(png::Compression::Balanced);
    encoder.set_filter(png::Filter::Adaptive);
    let mut writer = encoder.write_header().expect("in-memory PNG header");
    writer.write_image_data(buf).expect("in-memory PNG encoding");
    writer.finish().expect("in-memory PNG end");
    out
}
