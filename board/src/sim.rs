//! The Verilator build and run of the board top with the vendor cells swapped for their
//! behavioural twin (`--binary --timing`: the twin's PLL runs its own clocks by delays).

use std::path::{Path, PathBuf};
use std::process::Command;

#[derive(Debug, thiserror::Error)]
pub enum SimError {
    #[error("{what}: {error}")]
    Io { what: String, error: std::io::Error },
    #[error("{what} failed ({status}); its output:\n{output}")]
    Failed { what: String, status: std::process::ExitStatus, output: String },
    #[error("the bench ended without a recording: {0}")]
    NoRecording(String),
}

fn run(cmd: &mut Command, what: &str) -> Result<String, SimError> {
    let out = cmd.output().map_err(|error| SimError::Io { what: what.into(), error })?;
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    if !out.status.success() {
        return Err(SimError::Failed { what: what.into(), status: out.status, output: text });
    }
    Ok(text)
}

/// Verilates and compiles the bench over the RTL folder `rtl` (the vendor file left out) in
/// `work`; returns the executable.
pub fn build(rtl: &Path, work: &Path) -> Result<PathBuf, SimError> {
    std::fs::create_dir_all(work).map_err(|error| SimError::Io { what: format!("creating {}", work.display()), error })?;
    for (name, text) in crate::SIM_FILES {
        std::fs::write(work.join(name), text).map_err(|error| SimError::Io { what: format!("writing {name}"), error })?;
    }
    let mut sources: Vec<PathBuf> = std::fs::read_dir(rtl)
        .map_err(|error| SimError::Io { what: format!("reading {}", rtl.display()), error })?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "v") && !p.ends_with(crate::VENDOR_FILE))
        .collect();
    sources.sort();
    sources.extend(crate::SIM_FILES.iter().map(|(n, _)| work.join(n)));
    let obj = work.join("obj");
    let mut cmd = Command::new("verilator");
    cmd.args([
        "--binary",
        "--timing",
        "-Wno-fatal",
        "-Wno-lint",
        "-Wno-style",
        "--top-module",
        "board_tb",
        "-O3",
        "--timescale",
        "1ns/1ps",
    ])
    .args(["--x-assign", "unique", "--x-initial", "unique", "-j", "2", "-o", "board_sim"])
    .args(["-CFLAGS", "-O1"])
    .arg("--Mdir")
    .arg(&obj)
    .args(&sources);
    run(&mut cmd, "verilator")?;
    Ok(obj.join("board_sim"))
}

/// Runs the bench in `rtl` (where `$readmemh` finds the ROM image), registers powering up
/// random from `seed`; with `redraw`, F1 is pressed once the first drawing is done and the
/// recording follows the second. Returns the recording's path and the bench's output.
pub fn simulate(exe: &Path, rtl: &Path, work: &Path, seed: u64, redraw: bool) -> Result<(PathBuf, String), SimError> {
    let rec = work.join("recording.txt");
    let log = bench(exe, rtl, &rec, seed, if redraw { vec!["+redraw".into()] } else { vec![] })?;
    if !log.contains(" words at ") {
        return Err(SimError::NoRecording(log));
    }
    Ok((rec, log))
}

/// The UART source's run: the bench plays `stimulus` (crate::stream's file) on the serial line.
#[derive(Debug, Clone)]
pub struct Stream {
    pub stimulus: PathBuf,
    pub baud: u32,
    /// Log the frame buffer's writes and stop once drawing is done, instead of recording a frame.
    pub writes: bool,
    /// The bench gives up after this much simulated time.
    pub timeout_ms: u32,
}

/// What a UART run left: the recorded frame or the write log, and the bench's output.
pub struct StreamRun {
    pub recording: Option<PathBuf>,
    pub writes: Option<PathBuf>,
    pub log: String,
}

pub fn simulate_stream(exe: &Path, rtl: &Path, work: &Path, seed: u64, s: &Stream) -> Result<StreamRun, SimError> {
    let rec = work.join("recording.txt");
    let wlog = work.join("writes.txt");
    let abs = |p: &Path| std::path::absolute(p).unwrap_or(p.to_path_buf());
    let mut args =
        vec![format!("+stream={}", abs(&s.stimulus).display()), format!("+baud={}", s.baud), format!("+timeout_ms={}", s.timeout_ms)];
    if s.writes {
        let _ = std::fs::remove_file(&wlog);
        args.push(format!("+writes={}", abs(&wlog).display()));
    }
    let log = bench(exe, rtl, &rec, seed, args)?;
    if s.writes {
        if !log.contains("writes logged") {
            return Err(SimError::NoRecording(log));
        }
        return Ok(StreamRun { recording: None, writes: Some(wlog), log });
    }
    if !log.contains(" words at ") {
        return Err(SimError::NoRecording(log));
    }
    Ok(StreamRun { recording: Some(rec), writes: None, log })
}

fn bench(exe: &Path, rtl: &Path, rec: &Path, seed: u64, extra: Vec<String>) -> Result<String, SimError> {
    let _ = std::fs::remove_file(rec);
    let exe = std::path::absolute(exe).map_err(|error| SimError::Io { what: format!("{}", exe.display()), error })?;
    let mut cmd = Command::new(exe);
    cmd.current_dir(rtl)
        .arg(format!("+out={}", std::path::absolute(rec).unwrap_or(rec.to_path_buf()).display()))
        .arg("+verilator+rand+reset+2")
        .arg(format!("+verilator+seed+{}", seed.max(1)))
        .args(extra);
    run(&mut cmd, "the simulation")
}
