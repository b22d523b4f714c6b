//! `bench`'s stimulus and expected-output files (`scripts/bench-cosim`): the layout that the
//! harness's `bench`, the native C++ testbench (`bench/native_tb.cpp`) and the cocotb test
//! (`bench/cocotb/test_bench.py`) share, and the header's model description, one serde type
//! that the writer (`bench gen`) and the reader (`bench harness`) both use.
//!
//! Stimulus file (format 2): a header of 64 fixed bytes
//!   `magic "SSBSTIM2", u32 design (0 segment, 1 specular), u32 p, u32 xorshift32 start state,
//!    u32 valid_thr, u32 ready_thr, u32 spans, u64 outputs, u64 seed, u32 expected record bytes,
//!    u32 in_di width, u32 records_at, u32 model bytes`,
//! then the model's description ([`StimModel`] as JSON, `model bytes` long), zero-padded to
//! `records_at` (a multiple of 32), then one 32-byte record per span from `records_at`:
//! `u32 port[5], u32 outputs, u32 triangle, u32 y`, the ports being `in_x, in_len, in_i0, in_di,
//! 0` (segment) or `in_c, in_n, in_theta0, in_dtheta, in_len` (specular), as the port bits.
//! `outputs` is the number of segments (pixels) the span yields.
//!
//! Expected file: a 24-byte header `magic "SSBEXPT1", u32 design, u32 record bytes, u64 records`,
//! then one record per output in order: segment `u32 out_x | out_last << 31, u8 mask[ceil(p/8)],
//! u8 pix[p]` (masked lanes 0), zero-padded to a multiple of 4; specular `u16 out_spec,
//! u8 out_err, u8 out_last`. The traffic is [`crate::traffic`], from the header's state and
//! thresholds.
//!
//! Format 1 (`SSBSTIM1`, before the model was written down) is still read: its bytes 56..64 are
//! zero, its records start at 64, and it names the default configuration at its P (span
//! alignment), the only models it could be made for.

use crate::traffic::state_of;
use clap::{Parser, ValueEnum};
use golden::setup::Screen;
use golden::specular::BrdfK;
use hdl_gen::cli::ModelArgs;
use serde::{Deserialize, Serialize};
use std::io::{BufReader, Read};
use std::path::{Path, PathBuf};

/// A stimulus file's magic: these seven bytes, then its format's digit.
const STIM_MAGIC: &[u8; 7] = b"SSBSTIM";
/// The format `gen` writes.
const FORMAT: u8 = b'2';
const EXPECT_MAGIC: &[u8; 8] = b"SSBEXPT1";
/// The header's fixed part; format 2's model description follows it.
pub const HEADER: usize = 64;
/// The most bytes a model description may take: `generate`'s flags are a few hundred, so a
/// larger count is a garbage header, refused before anything is allocated for it.
const MODEL_LIMIT: u32 = 1 << 16;

/// A stimulus file, or a model, the bench cannot take.
#[derive(Debug, thiserror::Error)]
pub enum FileError {
    #[error("not a file")]
    NotAFile,
    #[error("{0}")]
    Io(#[from] std::io::Error),
    #[error("shorter than the {HEADER}-byte header of a bench stimulus file")]
    Short,
    #[error("not a bench stimulus file (no SSBSTIM header)")]
    NotStim,
    #[error("a bench stimulus file of format {0}, this bench reads formats 1 and 2: write it again with `bench gen`")]
    Format(String),
    #[error("a model description of {bytes} bytes and records at byte {at} do not fit")]
    ModelFit { bytes: u32, at: u32 },
    #[error("the model description: {0}")]
    ModelRead(std::io::Error),
    #[error("the model description: {0}")]
    ModelJson(#[from] serde_json::Error),
    #[error("the model's flags {flags:?}: {message}")]
    Flags { flags: Vec<String>, message: String },
    #[error("the header promises {spans} spans ({want} bytes), the file has {len} bytes")]
    Size { spans: u32, want: u64, len: u64 },
    #[error("unknown design {0} (0 segment, 1 specular)")]
    Design(u32),
    #[error("header fields out of range (record bytes, in_di width or traffic thresholds)")]
    Fields,
    #[error("traffic state is not state_of(seed)")]
    State,
    #[error("{0}")]
    Args(#[from] hdl_gen::cli::ArgsError),
    #[error("internal: the header's flags {0:?} name another model than the command line's")]
    Lost(Vec<String>),
}

/// What a stimulus file needs beyond its fixed fields, written as JSON into its header.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct StimModel {
    /// `hdl-gen generate`'s flags of the model the file was made for, every one written out
    /// (`--frac=8`), so that a later change of a default does not change what a file names. Read
    /// back through the same `hdl_gen::cli::ModelArgs` as the command line: a value `generate`
    /// refuses is refused with its message, and a user can `generate` the same Verilog.
    pub generate: Vec<String>,
    /// The screen the random triangles were drawn on (segment design; `None`: specular), so the
    /// file can be made again from its header.
    pub screen: Option<[u32; 2]>,
}

/// `generate`'s flags alone, as clap reads them from a [`StimModel`].
#[derive(Parser)]
#[command(name = "model", no_binary_name = true)]
struct ModelFlags {
    #[command(flatten)]
    model: ModelArgs,
}

/// The name clap gives a choice (`span`, `shift-add`).
fn choice<E: ValueEnum>(e: &E) -> String {
    e.to_possible_value().expect("no choice is hidden").get_name().to_string()
}

impl StimModel {
    /// The description of `m`, checked to read back as the same configuration, so that a flag
    /// this list forgot cannot make a file that names another model.
    pub fn of(m: &ModelArgs, screen: Option<Screen>) -> Result<StimModel, FileError> {
        let v = &m.variant;
        let mut generate = vec![
            format!("--p={}", m.seg.p),
            format!("--align={}", choice(&m.seg.align)),
            format!("--frac={}", v.format.frac),
            format!("--xbits={}", v.format.xbits),
            format!("--prefix={}", v.format.prefix),
            format!("--bfpi-arch={}", choice(&v.bfpi_arch)),
            format!("--fe-di={}", choice(&v.fe_di)),
            format!("--bus={}", choice(&v.bus)),
        ];
        // A target's choices are left to it, as the command line left them.
        generate.extend(v.fe_i0.map(|i| format!("--fe-i0={}", choice(&i))));
        generate.extend(v.pipeline.map(|l| format!("--pipeline={l}")));
        generate.extend(v.target.map(|t| format!("--target={}", choice(&t))));
        generate.extend(v.fe_setup.map(|f| format!("--fe-setup={}", choice(&f))));
        generate.extend(v.fe_span.map(|f| format!("--fe-span={}", choice(&f))));
        generate.extend(v.fe_div_bits.map(|b| format!("--fe-div-bits={b}")));
        match &v.brdf.brdf_k {
            None => {}
            Some(BrdfK::Auto { max_err }) => {
                generate.push("--brdf-k=auto".into());
                generate.push(format!("--max-rel-error={}", v.brdf.max_rel_error.unwrap_or(*max_err)));
            }
            Some(list) => generate.push(format!("--brdf-k={list}")),
        }
        let d = StimModel { generate, screen: screen.map(|s| [s.width, s.height]) };
        let want = m.options(None)?;
        if format!("{:?}", d.options()?) != format!("{want:?}") {
            return Err(FileError::Lost(d.generate));
        }
        Ok(d)
    }

    /// The model of a format-1 file: the default configuration at `p`, span alignment.
    pub fn format1(design: u32, p: u32) -> StimModel {
        match design {
            0 => StimModel { generate: vec![format!("--p={p}"), "--align=span".into()], screen: Some([640, 480]) },
            _ => StimModel { generate: Vec::new(), screen: None },
        }
    }

    /// `generate`'s options of the model, checked as the command line's are.
    pub fn options(&self) -> Result<hdl_gen::Options, FileError> {
        let flags = |message: String| FileError::Flags { flags: self.generate.clone(), message };
        let parsed = ModelFlags::try_parse_from(&self.generate).map_err(|e| {
            let text = e.to_string();
            flags(text.lines().next().unwrap_or_default().trim_start_matches("error: ").to_string())
        })?;
        parsed.model.options(None).map_err(|e| flags(e.to_string()))
    }
}

/// A stimulus file's header: its fixed fields and its model.
#[derive(Debug, Clone, PartialEq)]
pub struct Header {
    /// 0: the segment shader, 1: the specular unit.
    pub design: u32,
    pub p: u32,
    /// The traffic's xorshift32 start state ([`state_of`] the seed) and thresholds in 256ths.
    pub state: u32,
    pub valid_thr: u32,
    pub ready_thr: u32,
    pub spans: u32,
    /// Records of the expected file.
    pub outputs: u64,
    pub seed: u64,
    /// Bytes of one expected record.
    pub rec: u32,
    /// `in_di`'s width.
    pub dw: u32,
    pub model: StimModel,
}

/// Where a file's records start, after a model description of `model` bytes.
fn records_at(model: u32) -> u32 {
    (HEADER as u32 + model).next_multiple_of(32)
}

impl Header {
    /// The header in format 2: the fixed part, the model, padding up to the first record.
    pub fn bytes(&self) -> Vec<u8> {
        let model = serde_json::to_vec(&self.model).expect("a StimModel serialises");
        let model_bytes = u32::try_from(model.len()).ok().filter(|&n| n <= MODEL_LIMIT).expect("a model takes a few hundred bytes");
        let mut h = vec![0u8; records_at(model_bytes) as usize];
        h[..7].copy_from_slice(STIM_MAGIC);
        h[7] = FORMAT;
        let words = [self.design, self.p, self.state, self.valid_thr, self.ready_thr, self.spans];
        for (k, w) in words.iter().enumerate() {
            h[8 + 4 * k..12 + 4 * k].copy_from_slice(&w.to_le_bytes());
        }
        h[32..40].copy_from_slice(&self.outputs.to_le_bytes());
        h[40..48].copy_from_slice(&self.seed.to_le_bytes());
        h[48..52].copy_from_slice(&self.rec.to_le_bytes());
        h[52..56].copy_from_slice(&self.dw.to_le_bytes());
        h[56..60].copy_from_slice(&records_at(model_bytes).to_le_bytes());
        h[60..64].copy_from_slice(&model_bytes.to_le_bytes());
        h[HEADER..HEADER + model.len()].copy_from_slice(&model);
        h
    }

    /// The header of a stimulus file of `len` bytes, from its fixed part `h` and, in format 2,
    /// the model description read from `f`; every field checked against what `gen` writes, so
    /// a truncated, foreign or garbage file is refused before anything is sized by it. Returns
    /// the header and where the records start.
    pub fn parse(h: &[u8; HEADER], f: &mut impl Read, len: u64) -> Result<(Header, u64), FileError> {
        if &h[..7] != STIM_MAGIC {
            return Err(FileError::NotStim);
        }
        let w = |k: usize| u32::from_le_bytes(h[8 + 4 * k..12 + 4 * k].try_into().expect("4 bytes"));
        let (design, p) = (w(0), w(1));
        let (start, model) = match h[7] {
            b'1' => (HEADER as u32, StimModel::format1(design, p)),
            FORMAT => {
                let (start, bytes) = (w(12), w(13));
                if bytes > MODEL_LIMIT || start != records_at(bytes) || start as u64 > len {
                    return Err(FileError::ModelFit { bytes, at: start });
                }
                let mut text = vec![0u8; bytes as usize];
                f.read_exact(&mut text).map_err(FileError::ModelRead)?;
                let mut pad = vec![0u8; (start - HEADER as u32 - bytes) as usize];
                f.read_exact(&mut pad).map_err(FileError::ModelRead)?;
                (start, serde_json::from_slice(&text)?)
            }
            v => return Err(FileError::Format(v.escape_ascii().to_string())),
        };
        let header = Header {
            design,
            p,
            state: w(2),
            valid_thr: w(3),
            ready_thr: w(4),
            spans: w(5),
            outputs: u64::from_le_bytes(h[32..40].try_into().expect("8 bytes")),
            seed: u64::from_le_bytes(h[40..48].try_into().expect("8 bytes")),
            rec: w(10),
            dw: w(11),
            model,
        };
        let want = start as u64 + 32 * header.spans as u64;
        if len != want {
            return Err(FileError::Size { spans: header.spans, want, len });
        }
        let rec = match header.design {
            0 => seg_record_bytes(header.p.min(256)),
            1 => 4,
            d => return Err(FileError::Design(d)),
        };
        if header.rec != rec || !(1..=32).contains(&header.dw) || header.valid_thr > 256 || header.ready_thr > 256 {
            return Err(FileError::Fields);
        }
        if header.state != state_of(header.seed) {
            return Err(FileError::State);
        }
        Ok((header, start as u64))
    }
}

/// One stimulus record.
pub fn stim_record(ports: [u32; 5], outputs: u32, triangle: u32, y: u32) -> [u8; 32] {
    let mut r = [0u8; 32];
    for (k, w) in ports.iter().chain(&[outputs, triangle, y]).enumerate() {
        r[4 * k..4 * k + 4].copy_from_slice(&w.to_le_bytes());
    }
    r
}

/// The expected file's header.
pub fn expect_header(design: u32, rec: u32, records: u64) -> [u8; 24] {
    let mut h = [0u8; 24];
    h[..8].copy_from_slice(EXPECT_MAGIC);
    h[8..12].copy_from_slice(&design.to_le_bytes());
    h[12..16].copy_from_slice(&rec.to_le_bytes());
    h[16..24].copy_from_slice(&records.to_le_bytes());
    h
}

/// Bytes of one segment record of the expected file at P.
pub fn seg_record_bytes(p: u32) -> u32 {
    (4 + p.div_ceil(8) + p).next_multiple_of(4)
}

/// A stimulus file [`read_stim`] refuses, by name.
#[derive(Debug, thiserror::Error)]
#[error("{}: {error}", path.display())]
pub struct ReadError {
    pub path: PathBuf,
    pub error: FileError,
}

/// The header and the records (at most `limit`, 0: all) of a stimulus file; the file's size
/// must be what its header says, so nothing is allocated on a garbage count.
pub fn read_stim(path: &Path, limit: usize) -> Result<(Header, Vec<[u32; 8]>), ReadError> {
    let bad = |error: FileError| ReadError { path: path.to_path_buf(), error };
    let file = std::fs::File::open(path).map_err(|e| bad(e.into()))?;
    let meta = file.metadata().map_err(|e| bad(e.into()))?;
    if !meta.is_file() {
        return Err(bad(FileError::NotAFile));
    }
    let mut f = BufReader::new(file);
    let mut h = [0u8; HEADER];
    f.read_exact(&mut h).map_err(|_| bad(FileError::Short))?;
    // The model description, if any, is read here too: `f` is then at the first record.
    let (header, _) = Header::parse(&h, &mut f, meta.len()).map_err(bad)?;
    let n = match limit {
        0 => header.spans as usize,
        l => l.min(header.spans as usize),
    };
    let mut recs = Vec::with_capacity(n);
    let mut r = [0u8; 32];
    for _ in 0..n {
        f.read_exact(&mut r).map_err(|e| bad(e.into()))?;
        recs.push(std::array::from_fn(|k| u32::from_le_bytes(r[4 * k..4 * k + 4].try_into().expect("4 bytes"))));
    }
    Ok((header, recs))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(flags: &[&str]) -> ModelArgs {
        ModelFlags::try_parse_from(flags).unwrap().model
    }

    fn header(model: StimModel) -> Header {
        Header {
            design: 0,
            p: 8,
            state: state_of(5),
            valid_thr: 179,
            ready_thr: 179,
            spans: 0,
            outputs: 0,
            seed: 5,
            rec: seg_record_bytes(8),
            dw: 21,
            model,
        }
    }

    /// Every option of `generate` survives the header: written, parsed back, the same options;
    /// a flag the writer forgets is caught (the negative control: a description without one).
    #[test]
    fn the_model_round_trips_through_the_header() {
        let configs: &[&[&str]] = &[
            &[],
            &["--p", "16", "--align", "screen", "--frac", "10", "--xbits", "11", "--prefix", "a_"],
            &["--bfpi-arch", "naive", "--fe-di", "scanline", "--fe-div-bits", "2", "--pipeline", "2", "--bus", "axis"],
            &["--fe-i0", "incremental", "--brdf-k", "1,2,3,9"],
            // The target as a flag of its own (the auto plan's search takes most of this test).
            &["--brdf-k", "auto", "--max-rel-error", "3%"],
        ];
        for flags in configs {
            let m = args(flags);
            let d = StimModel::of(&m, Some(Screen { width: 320, height: 240 })).unwrap_or_else(|e| panic!("{flags:?}: {e}"));
            let bytes = header(d.clone()).bytes();
            assert_eq!(bytes.len() % 32, 0);
            let (back, at) = Header::parse(bytes[..HEADER].try_into().unwrap(), &mut &bytes[HEADER..], bytes.len() as u64).unwrap();
            assert_eq!((back.model.clone(), at), (d, bytes.len() as u64), "{flags:?}");
            assert_eq!(format!("{:?}", back.model.options().unwrap()), format!("{:?}", m.options(None).unwrap()), "{flags:?}");
        }
        let mut forgot = StimModel::of(&args(&["--pipeline", "2"]), None).unwrap();
        forgot.generate.retain(|f| !f.starts_with("--pipeline"));
        assert_ne!(format!("{:?}", forgot.options().unwrap()), format!("{:?}", args(&["--pipeline", "2"]).options(None).unwrap()));
    }

    /// A format-1 header (no description, records at 64) reads as the default model at its P.
    #[test]
    fn format_1_reads_as_the_default_model_at_its_p() {
        let mut bytes = header(StimModel::format1(0, 8)).bytes();
        bytes.truncate(HEADER);
        bytes[7] = b'1';
        bytes[56..64].fill(0);
        let (h, at) = Header::parse(bytes[..].try_into().unwrap(), &mut &b""[..], HEADER as u64).unwrap();
        assert_eq!(at, HEADER as u64);
        assert_eq!(format!("{:?}", h.model.options().unwrap()), format!("{:?}", args(&["--p", "8"]).options(None).unwrap()));
    }
}
