//! `render` through the RTL: the fill rule holds exactly for triangle files (meshes and fans
//! cover every pixel of a 64x64 screen exactly once, equal to golden and to the f64 reference),
//! scenes match golden, and the command line behaves (exit 2 naming a malformed line, nothing
//! written; the same command writes the same bytes).

use golden::raster::{compare, reference_triangle, Frame, RefFrame};
use golden::rng::SeedRng;
use golden::setup::{Screen, Triangle, Vertex};
use golden::Align;
use rand::{Rng, SeedableRng};
use std::path::{Path, PathBuf};
use std::process::Command;
use verilator_harness::registry::{default_model_args, require_segment_model, require_specular_model, SEGMENT_MODELS};
use verilator_harness::render::{run, scene_job, triangles_job_of, SceneKind, BACKGROUND};

const SCREEN: Screen = Screen { width: 64, height: 64 };

fn tri(v: [[f64; 3]; 3]) -> Triangle {
    Triangle { v: v.map(|[x, y, i]| Vertex { x, y, i }) }
}

/// Triangle sets that each cover the whole 64x64 screen with shared edges: a square cut along
/// its diagonal, a jittered mesh with vertices on pixel centres, corners and anywhere, and a fan
/// around a pixel centre.
fn tilings(rng: &mut SeedRng) -> Vec<(&'static str, Vec<Triangle>)> {
    let s = 64.0;
    let mut out = vec![(
        "square on its diagonal",
        vec![tri([[0.0, 0.0, 10.0], [s, 0.0, 200.0], [s, s, 90.0]]), tri([[0.0, 0.0, 10.0], [s, s, 90.0], [0.0, s, 255.0]])],
    )];
    let cell = 9.0;
    let n = 10;
    let mut grid = vec![[0.0; 3]; n * n];
    for j in 0..n {
        for i in 0..n {
            let jit = |rng: &mut SeedRng| match rng.gen_range(0..3) {
                0 => 0.0,
                1 => rng.gen_range(-3..=3) as f64 * 0.5,
                _ => rng.gen_range(-1.7..1.7),
            };
            let edge = |k: usize| k == 0 || k == n - 1;
            let x = (i as f64 - 1.0) * cell + 0.5 + if edge(i) { 0.0 } else { jit(rng) };
            let y = (j as f64 - 1.0) * cell + 0.5 + if edge(j) { 0.0 } else { jit(rng) };
            grid[j * n + i] = [x, y, rng.gen_range(0.0..=255.0)];
        }
    }
    let mut mesh = Vec::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let [a, b, c, d] = [grid[j * n + i], grid[j * n + i + 1], grid[(j + 1) * n + i + 1], grid[(j + 1) * n + i]];
            if (i + j) % 2 == 0 {
                mesh.extend([tri([a, b, c]), tri([a, c, d])]);
            } else {
                mesh.extend([tri([a, b, d]), tri([b, c, d])]);
            }
        }
    }
    out.push(("jittered mesh", mesh));
    for centre in [[32.5, 32.5], [20.0, 41.0]] {
        let spokes = 12;
        let c = [centre[0], centre[1], 128.0];
        let corner = |k: usize| {
            let a = std::f64::consts::TAU * k as f64 / spokes as f64;
            [centre[0] + 200.0 * a.cos(), centre[1] + 200.0 * a.sin(), (k * 20) as f64]
        };
        out.push(("fan", (0..spokes).map(|k| tri([c, corner(k), corner(k + 1)])).collect()));
    }
    out
}

#[test]
fn triangle_files_follow_the_fill_rule_exactly() {
    let seed = verilator_harness::seed("triangle_files_follow_the_fill_rule_exactly");
    let mut rng = SeedRng::seed_from_u64(seed);
    let sets = tilings(&mut rng);
    let wanted = [(1, Align::Span), (8, Align::Span), (8, Align::Screen), (64, Align::Screen)];
    let mut models: Vec<_> =
        wanted.iter().filter_map(|&(p, a)| require_segment_model(p, a, &format!("render: triangle files on p = {p} {a}"))).collect();
    // A COSIM_RTL_DIR build also runs the folder's own shader, whatever its p and alignment.
    if verilator_harness::registry::rtl_dir().is_some() {
        models.extend(SEGMENT_MODELS.iter().filter(|m| !wanted.contains(&(m.cfg.p, m.cfg.align))));
    }
    for info in models {
        for (name, tris) in &sets {
            let what = format!("{} on {name} (seed {seed})", info.tag);
            let job = triangles_job_of(tris, &info.cfg, &SCREEN).unwrap();
            let o = run(&job, info, None, |_| {});
            assert!(o.cosim_ok(), "{what}: {:?}", o.segment[0].mismatches);
            assert!(o.coverage.iter().all(|&c| c == 1), "{what}: RTL lanes cover a pixel {:?} times", o.coverage.iter().find(|&&c| c != 1));
            assert!(job.owner.iter().all(|&t| t != BACKGROUND), "{what}");
            assert_eq!(o.rtl, o.golden, "{what}: RTL image differs from golden");
            // The exact f64 rasterizer decides coverage independently: same pixels, within 1.
            let mut frame = Frame::new(SCREEN.width, SCREEN.height);
            let mut reference = RefFrame::new(SCREEN.width, SCREEN.height);
            for y in 0..SCREEN.height {
                for x in 0..SCREEN.width {
                    frame.set(x, y, o.rtl[(y * SCREEN.width + x) as usize]);
                }
            }
            for t in tris {
                reference_triangle(&SCREEN, t, &mut reference).unwrap();
            }
            let c = compare(&frame, &reference);
            assert!(c.passed(), "{what}: {c}");
        }
    }
}

#[test]
fn later_triangles_are_drawn_over_earlier_ones() {
    let Some(info) = require_segment_model(8, Align::Span, "render: drawing order") else { return };
    let big = tri([[0.0, 0.0, 50.0], [64.0, 0.0, 50.0], [0.0, 64.0, 50.0]]);
    let small = tri([[4.0, 4.0, 200.0], [20.0, 4.0, 200.0], [4.0, 20.0, 200.0]]);
    for (order, want) in [([big, small], 200), ([small, big], 50)] {
        let job = triangles_job_of(&order, &info.cfg, &SCREEN).unwrap();
        let o = run(&job, info, None, |_| {});
        assert_eq!(o.rtl, o.golden);
        assert_eq!(o.rtl[(8 * 64 + 8) as usize], want);
        assert_eq!(o.rtl[(63 * 64 + 63) as usize], 0, "background");
        assert_eq!(o.coverage[(8 * 64 + 8) as usize], 2);
    }
}

#[test]
fn scenes_match_golden() {
    let Some(spec) = require_specular_model("render: the scenes") else { return };
    let screen = Screen { width: 128, height: 96 };
    for (kind, p, align) in [(SceneKind::Sphere, 8, Align::Span), (SceneKind::Torus, 16, Align::Screen)] {
        let Some(info) = require_segment_model(p, align, &format!("render: the {kind:?} scene on p = {p} {align}")) else { continue };
        let job = scene_job(kind, 40, &info.cfg, &screen).unwrap();
        assert!(job.triangles >= 5000 && job.drawn < job.triangles, "{kind:?}: culling");
        let o = run(&job, info, Some(spec), |_| {});
        assert!(o.cosim_ok(), "{kind:?}");
        assert_eq!(o.rtl, o.golden, "{kind:?}: RTL image differs from golden");
        assert_eq!(&o.rtl[..3], &[0, 0, 0], "{kind:?}: background in the corner");
        // A white highlight: some pixel saturates in every channel.
        assert!(o.rtl.chunks(3).any(|px| px.iter().all(|&v| v >= 250)), "{kind:?}: no highlight");
        let spec_report = o.specular.as_ref().unwrap();
        assert_eq!(spec_report.pixels, job.shaded_pixels());
    }
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("segshade-render-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn render(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_render")).args(args).output().expect("render runs")
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn render_command_writes_matching_deterministic_images() {
    if require_segment_model(8, Align::Screen, "render: the render command on p = 8 screen").is_none() {
        return;
    }
    let dir = scratch("cli");
    let file = dir.join("two.txt");
    std::fs::write(&file, "# two triangles sharing the diagonal\n0 0 10  64 0 200  64 64 90\n\n0 0 10 64 64 90 0 64 255 # second\n")
        .unwrap();
    let out = dir.join("two.png");
    let args = ["--triangles", s(&file), "--p", "8", "--align", "screen", "--width", "64", "--height", "64", "--diff", "--out", s(&out)];
    let r = render(&args);
    assert_eq!(r.status.code(), Some(0), "{}{}", String::from_utf8_lossy(&r.stdout), String::from_utf8_lossy(&r.stderr));
    let stdout = String::from_utf8_lossy(&r.stdout);
    assert!(stdout.contains("pixels per clock") && stdout.contains("matches golden"), "{stdout}");
    let rtl = std::fs::read(&out).unwrap();
    let golden = std::fs::read(dir.join("two.golden.png")).unwrap();
    assert_eq!(rtl, golden);
    assert!(dir.join("two.diff.png").exists());
    let mut reader = png::Decoder::new(std::io::Cursor::new(&rtl)).read_info().unwrap();
    let mut img = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut img).unwrap();
    assert_eq!((info.width, info.height, info.color_type), (64, 64, png::ColorType::Grayscale));
    assert!(img[..info.buffer_size()].iter().all(|&p| p > 0), "a pixel is left uncovered");
    let again = render(&args);
    assert_eq!(again.status.code(), Some(0));
    assert_eq!(std::fs::read(&out).unwrap(), rtl, "same command, different bytes");
    // No temporary file is left behind.
    let names: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    assert!(names.iter().all(|n| !n.contains(".tmp")), "{names:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn render_command_rejects_a_malformed_line() {
    let Some(model) = default_model_args("render: the render command's bad input") else { return };
    let model: Vec<&str> = model.iter().map(String::as_str).collect();
    // The default model, or the one this build has: a missing model would be the error instead.
    let render_on = |args: &[&str]| render(&[&model[..], args].concat());
    let dir = scratch("bad");
    let out = dir.join("bad.png");
    for (text, want) in [
        ("0 0 10 64 0 200 64 64 90\n# fine\n0 0 10 64 64 90 0 64\n", "line 3"),
        ("\n\n\n1 2 3 4 5 6 7 8 x\n", "line 4"),
        ("0 0 10 64 0 200 64 64 300\n", "line 1"),
    ] {
        let file = dir.join("bad.txt");
        std::fs::write(&file, text).unwrap();
        let r = render_on(&["--triangles", s(&file), "--width", "64", "--height", "64", "--out", s(&out)]);
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{err}");
        assert!(err.starts_with("error: ") && err.contains(want) && err.lines().count() == 1, "{err}");
        assert!(!out.exists() && !dir.join("bad.golden.png").exists());
    }
    let r = render_on(&["--triangles", "/nonexistent/file.txt", "--out", s(&out)]);
    assert_eq!(r.status.code(), Some(2));
    let r = render(&["--scene", "sphere", "--p", "3", "--out", s(&out)]);
    assert_eq!(r.status.code(), Some(2));
    let r = render_on(&["--scene", "sphere", "--out", "/nonexistent/dir/x.png"]);
    assert_eq!(r.status.code(), Some(2));
    assert!(!out.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
