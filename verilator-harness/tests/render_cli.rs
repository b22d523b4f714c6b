//! The `render` command's output: a lit scene (three channel threads and the specular unit)
//! rendered twice writes the same bytes, and the summary names the models that actually ran.

use golden::Align;
use std::path::PathBuf;
use std::process::{Command, Output};
use verilator_harness::registry::{require, require_segment_model, require_specular_model, TRISHADER_MODELS};

fn render(args: &[&str]) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_render")).args(args).output().expect("render runs");
    assert_eq!(
        out.status.code(),
        Some(0),
        "render {args:?}: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("segshade-render-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn a_scene_renders_to_the_same_bytes_twice() {
    if require_segment_model(8, Align::Span, "render_cli: a scene twice").is_none()
        || require_specular_model("render_cli: a scene twice").is_none()
    {
        return;
    }
    let dir = scratch("twice");
    let mut made = Vec::new();
    for k in 0..2 {
        let out = dir.join(format!("torus{k}.png"));
        render(&["--scene", "torus", "--width", "96", "--height", "72", "--diff", "--quiet", "--out", out.to_str().unwrap()]);
        made.push(["", ".golden", ".diff"].map(|s| std::fs::read(dir.join(format!("torus{k}{s}.png"))).unwrap()));
    }
    for (a, b) in made[0].iter().zip(&made[1]) {
        assert!(a.len() > 100 && a == b, "the same command wrote other bytes");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_summary_names_the_models_that_ran() {
    let dir = scratch("summary");
    let file = dir.join("one.txt");
    std::fs::write(&file, "100 100 10  300 120 200  180 260 90\n").unwrap();
    let out = dir.join("one.png");
    let base = ["--triangles", file.to_str().unwrap(), "--p", "8", "--width", "640", "--height", "480", "--out", out.to_str().unwrap()];
    let first_line = |extra: &[&str]| {
        let r = render(&[&base[..], extra].concat());
        String::from_utf8_lossy(&r.stdout).lines().next().unwrap_or_default().to_string()
    };
    if let Some(seg) = require_segment_model(8, Align::Span, "render_cli: the summary, host set-up") {
        let line = first_line(&[]);
        assert!(line.contains(&format!("model {} x 1 channel(s)", seg.tag)), "{line}");
    }
    let tri =
        TRISHADER_MODELS.iter().find(|m| m.cfg.p == 8 && m.cfg.align == Align::Span && m.screen.width == 640 && m.screen.height == 480);
    if let Some(tri) = require(tri, "tris_p8_span", "render_cli: the summary, RTL front-end") {
        let line = first_line(&["--frontend", "rtl"]);
        assert!(line.contains(&format!("model {} x 1 channel(s)", tri.tag)), "names the front-end chain that ran: {line}");
        assert!(!line.contains("seg_p"), "names a spans-fed shader that did not run: {line}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
