//! ROM images and their text formats, whatever the ROM holds.
//!
//! The specular unit has two ROMs (SPEC §3): the BRDF ROM holding the `cos^k` curves and
//! the n-table ("NK") ROM that turns `n` into a table select and an argument scale. The plan
//! computes their words once (`SpecularPlan::brdf_rom`, `SpecularPlan::nk_rom`); this module
//! knows nothing of what they mean.
//!
//! Three text formats are written and read back: `$readmemh` hex (what the generated
//! Verilog loads), Intel MIF and Xilinx COE (for vendor IP flows). Output is deterministic:
//! no dates, no tool versions.

use serde::{Deserialize, Serialize};
use std::fmt::Write as _;

/// Default file names of the two images, also the default of the RTL's file parameter.
pub const BRDF_HEX: &str = "specular_brdf_rom.hex";
pub const NK_HEX: &str = "specular_nk_rom.hex";

/// One ROM image: `depth = words.len()` words of `width` bits each.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Rom {
    pub name: String,
    pub width: u32,
    pub words: Vec<u64>,
}

/// The text formats a ROM image can be written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum RomFormat {
    /// Verilog `$readmemh`: one word per line, `//` comments.
    Hex,
    /// Intel (Altera) Memory Initialization File.
    Mif,
    /// Xilinx coefficient file.
    Coe,
}

impl RomFormat {
    pub const ALL: [RomFormat; 3] = [RomFormat::Hex, RomFormat::Mif, RomFormat::Coe];
    pub fn extension(self) -> &'static str {
        match self {
            RomFormat::Hex => "hex",
            RomFormat::Mif => "mif",
            RomFormat::Coe => "coe",
        }
    }
}

/// Bits needed to address `depth` words (at least 1, so a port never has width 0).
pub fn addr_bits(depth: usize) -> u32 {
    (usize::BITS - depth.saturating_sub(1).leading_zeros()).max(1)
}

impl Rom {
    /// A ROM; panics if a word does not fit `width`, because that is a bug in its builder.
    pub fn new(name: &str, width: u32, words: Vec<u64>) -> Rom {
        assert!((1..=64).contains(&width), "ROM width {width} out of 1..64");
        if width < 64 {
            if let Some((a, w)) = words.iter().enumerate().find(|(_, &w)| w >> width != 0) {
                panic!("ROM {name}: word {w:#x} at {a} does not fit {width} bits");
            }
        }
        Rom { name: name.to_string(), width, words }
    }

    pub fn depth(&self) -> usize {
        self.words.len()
    }
    pub fn addr_bits(&self) -> u32 {
        addr_bits(self.depth())
    }
    /// Storage in bits: what "fewer bits" in SPEC §4 counts.
    pub fn bits(&self) -> u64 {
        self.depth() as u64 * self.width as u64
    }
    fn hex_digits(&self) -> usize {
        self.width.div_ceil(4) as usize
    }

    pub fn to_text(&self, format: RomFormat) -> String {
        match format {
            RomFormat::Hex => self.to_hex(),
            RomFormat::Mif => self.to_mif(),
            RomFormat::Coe => self.to_coe(),
        }
    }

    /// `$readmemh` image: a comment line, then one zero-padded lowercase word per line.
    pub fn to_hex(&self) -> String {
        let d = self.hex_digits();
        let mut s = format!("// {}: {} x {} bits\n", self.name, self.depth(), self.width);
        for w in &self.words {
            let _ = writeln!(s, "{w:0d$x}");
        }
        s
    }

    /// Intel MIF, one `address : word;` line per word (no run-length ranges, so a diff of two
    /// images reads line by line).
    pub fn to_mif(&self) -> String {
        let d = self.hex_digits();
        let mut s = format!(
            "-- {}: {} x {} bits\nWIDTH={};\nDEPTH={};\nADDRESS_RADIX=UNS;\nDATA_RADIX=HEX;\n\nCONTENT BEGIN\n",
            self.name,
            self.depth(),
            self.width,
            self.width,
            self.depth()
        );
        for (a, w) in self.words.iter().enumerate() {
            let _ = writeln!(s, "\t{a} : {w:0d$X};");
        }
        s.push_str("END;\n");
        s
    }

    /// Xilinx COE: radix 16, comma-separated vector ending in `;`.
    pub fn to_coe(&self) -> String {
        let d = self.hex_digits();
        let mut s = format!(
            "; {}: {} x {} bits\nmemory_initialization_radix=16;\nmemory_initialization_vector=\n",
            self.name,
            self.depth(),
            self.width
        );
        for (a, w) in self.words.iter().enumerate() {
            let end = if a + 1 == self.depth() { ';' } else { ',' };
            let _ = writeln!(s, "{w:0d$x}{end}");
        }
        if self.words.is_empty() {
            s.push_str(";\n");
        }
        s
    }

    /// Reads any of the three formats back into a ROM of the given name and width.
    ///
    /// Nothing in the flow reads a ROM image back (the RTL loads the hex with `$readmemh`, vendor
    /// tools the MIF and COE): this and the `parse_*` readers below serve the tests, golden's
    /// round trips and `hdl-gen/tests/specular_cli.rs`, which read what `hdl-gen rom` wrote. They
    /// are public for that integration test, and strict enough to catch a writer that drifts.
    pub fn parse(name: &str, width: u32, format: RomFormat, text: &str) -> Result<Rom, RomParseError> {
        let words = match format {
            RomFormat::Hex => parse_hex(text)?,
            RomFormat::Mif => {
                let (declared, words) = parse_mif(text)?;
                if declared != width {
                    return Err(RomParseError::MifWidth { declared, expected: width });
                }
                words
            }
            RomFormat::Coe => parse_coe(text)?,
        };
        if width < 64 {
            if let Some((addr, &word)) = words.iter().enumerate().find(|(_, &w)| w >> width != 0) {
                return Err(RomParseError::WordWidth { word, addr, width });
            }
        }
        Ok(Rom { name: name.to_string(), width, words })
    }
}

/// A ROM image text that does not read ([`Rom::parse`] and the `parse_*` readers).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum RomParseError {
    #[error("unterminated /* comment")]
    UnterminatedComment,
    #[error("stray '/' in hex image")]
    StraySlash,
    #[error("bad hex token '{token}': {error}")]
    HexToken { token: String, error: std::num::ParseIntError },
    #[error("bad number '{text}': {error}")]
    Number { text: String, error: std::num::ParseIntError },
    #[error("unsupported radix '{0}'")]
    Radix(String),
    #[error("address {0:#x} is beyond any ROM this project builds")]
    Address(usize),
    /// A part the format requires is missing (`WIDTH`, `DEPTH`, `CONTENT`, ...).
    #[error("{format} has no {part}")]
    Missing { format: &'static str, part: &'static str },
    #[error("unknown {format} field '{field}'")]
    Field { format: &'static str, field: String },
    #[error("bad {format} statement '{statement}'")]
    Statement { format: &'static str, statement: String },
    #[error("MIF range '{0}' needs exactly one word")]
    MifRangeWords(String),
    #[error("MIF address {addr} beyond DEPTH={depth}")]
    MifAddress { addr: usize, depth: usize },
    #[error("MIF declares WIDTH={declared}, expected {expected}")]
    MifWidth { declared: u32, expected: u32 },
    #[error("word {word:#x} at address {addr} does not fit {width} bits")]
    WordWidth { word: u64, addr: usize, width: u32 },
}

fn put(words: &mut Vec<u64>, addr: usize, w: u64) -> Result<(), RomParseError> {
    // Cap the growth so a corrupt `@ffffffff` cannot allocate gigabytes.
    if addr >= 1 << 24 {
        return Err(RomParseError::Address(addr));
    }
    if words.len() <= addr {
        words.resize(addr + 1, 0);
    }
    words[addr] = w;
    Ok(())
}

fn strip_c_comments(text: &str) -> Result<String, RomParseError> {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(i) = rest.find('/') {
        out.push_str(&rest[..i]);
        let tail = &rest[i..];
        if tail.starts_with("//") {
            rest = tail.find('\n').map_or("", |j| &tail[j..]);
        } else if tail.starts_with("/*") {
            let j = tail.find("*/").ok_or(RomParseError::UnterminatedComment)?;
            out.push(' ');
            rest = &tail[j + 2..];
        } else {
            return Err(RomParseError::StraySlash);
        }
    }
    out.push_str(rest);
    Ok(out)
}

/// `$readmemh` text: whitespace-separated hex words, `//` and `/* */` comments, `@addr`
/// jumps; locations never written read as 0. `_` inside a number is ignored as in Verilog.
/// For tests (see [`Rom::parse`]).
pub fn parse_hex(text: &str) -> Result<Vec<u64>, RomParseError> {
    let mut words = Vec::new();
    let mut addr = 0usize;
    for tok in strip_c_comments(text)?.split_whitespace() {
        let (jump, digits) = match tok.strip_prefix('@') {
            Some(d) => (true, d),
            None => (false, tok),
        };
        let digits: String = digits.chars().filter(|&c| c != '_').collect();
        let v = u64::from_str_radix(&digits, 16).map_err(|error| RomParseError::HexToken { token: tok.into(), error })?;
        if jump {
            addr = v as usize;
        } else {
            put(&mut words, addr, v)?;
            addr += 1;
        }
    }
    Ok(words)
}

fn radix_of(s: &str) -> Result<u32, RomParseError> {
    match s.trim().to_ascii_uppercase().as_str() {
        "HEX" | "16" => Ok(16),
        "UNS" | "DEC" | "10" => Ok(10),
        "BIN" | "2" => Ok(2),
        "OCT" | "8" => Ok(8),
        r => Err(RomParseError::Radix(r.into())),
    }
}

fn num(s: &str, radix: u32) -> Result<u64, RomParseError> {
    u64::from_str_radix(s.trim(), radix).map_err(|error| RomParseError::Number { text: s.trim().into(), error })
}

/// Intel MIF: the header's WIDTH, DEPTH and radices, then `addr : w w ...;` or
/// `[lo..hi] : w;` lines; `--` and `% %` comments. Returns (width, words of DEPTH). For tests
/// (see [`Rom::parse`]).
pub fn parse_mif(text: &str) -> Result<(u32, Vec<u64>), RomParseError> {
    let missing = |part| RomParseError::Missing { format: "MIF", part };
    let statement = |s: &str| RomParseError::Statement { format: "MIF", statement: s.into() };
    let mut clean = String::with_capacity(text.len());
    let mut in_pct = false;
    for line in text.lines() {
        let line = line.split("--").next().unwrap_or("");
        for c in line.chars() {
            if c == '%' {
                in_pct = !in_pct;
            } else if !in_pct {
                clean.push(c);
            }
        }
        clean.push('\n');
    }
    let upper = clean.to_ascii_uppercase();
    let body_at = upper.find("CONTENT").ok_or(missing("CONTENT section"))?;
    let (mut width, mut depth, mut ar, mut dr) = (None, None, 16, 16);
    for stmt in upper[..body_at].split(';') {
        if let Some((k, v)) = stmt.split_once('=') {
            match k.trim() {
                "WIDTH" => width = Some(num(v, 10)? as u32),
                "DEPTH" => depth = Some(num(v, 10)? as usize),
                "ADDRESS_RADIX" => ar = radix_of(v)?,
                "DATA_RADIX" => dr = radix_of(v)?,
                other => return Err(RomParseError::Field { format: "MIF", field: other.into() }),
            }
        }
    }
    let width = width.ok_or(missing("WIDTH"))?;
    let depth = depth.ok_or(missing("DEPTH"))?;
    let body = &upper[body_at + "CONTENT".len()..];
    let body = body.trim_start().strip_prefix("BEGIN").ok_or(missing("BEGIN after CONTENT"))?;
    let end = body.rfind("END").ok_or(missing("END of its CONTENT"))?;
    let mut words = vec![0u64; depth];
    for stmt in body[..end].split(';').map(str::trim).filter(|s| !s.is_empty()) {
        let (a, d) = stmt.split_once(':').ok_or_else(|| statement(stmt))?;
        let a = a.trim();
        let (lo, hi) = match a.strip_prefix('[').and_then(|r| r.strip_suffix(']')) {
            Some(r) => {
                let (lo, hi) = r.split_once("..").ok_or_else(|| statement(stmt))?;
                (num(lo, ar)? as usize, Some(num(hi, ar)? as usize))
            }
            None => (num(a, ar)? as usize, None),
        };
        let data: Vec<u64> = d.split_whitespace().map(|t| num(t, dr)).collect::<Result<_, _>>()?;
        // A range repeats its (single) word; a plain address takes a run of words.
        let cells: Vec<(usize, u64)> = match hi {
            Some(hi) if data.len() == 1 => (lo..=hi).map(|i| (i, data[0])).collect(),
            Some(_) => return Err(RomParseError::MifRangeWords(a.into())),
            None => data.iter().enumerate().map(|(i, &w)| (lo + i, w)).collect(),
        };
        for (i, w) in cells {
            *words.get_mut(i).ok_or(RomParseError::MifAddress { addr: i, depth })? = w;
        }
    }
    Ok((width, words))
}

/// Xilinx COE: `memory_initialization_radix=R;` and `memory_initialization_vector=` followed
/// by words separated by commas or whitespace, ended by `;`. `;` starts a comment elsewhere.
/// For tests (see [`Rom::parse`]).
pub fn parse_coe(text: &str) -> Result<Vec<u64>, RomParseError> {
    // A line starting with ';' is a comment; elsewhere ';' ends a statement.
    let body: String = text.lines().filter(|l| !l.trim_start().starts_with(';')).flat_map(|l| [l, "\n"]).collect();
    let mut radix = 10;
    let mut vector = None;
    for stmt in body.split(';').map(str::trim).filter(|s| !s.is_empty()) {
        let (k, v) = stmt.split_once('=').ok_or_else(|| RomParseError::Statement { format: "COE", statement: stmt.into() })?;
        match k.trim().to_ascii_lowercase().as_str() {
            "memory_initialization_radix" => radix = num(v, 10)? as u32,
            "memory_initialization_vector" => vector = Some(v.to_string()),
            other => return Err(RomParseError::Field { format: "COE", field: other.into() }),
        }
    }
    let v = vector.ok_or(RomParseError::Missing { format: "COE", part: "memory_initialization_vector" })?;
    v.split(|c: char| c == ',' || c.is_whitespace()).filter(|t| !t.is_empty()).map(|t| num(t, radix)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Rom {
        Rom::new("t", 13, (0..300u64).map(|i| (i * 7919 + 3) % (1 << 13)).collect())
    }

    #[test]
    fn rom_round_trips_through_every_format() {
        for rom in [sample(), Rom::new("one", 1, vec![1, 0, 1]), Rom::new("e", 8, vec![])] {
            for f in RomFormat::ALL {
                let text = rom.to_text(f);
                let back = Rom::parse(&rom.name, rom.width, f, &text).unwrap();
                assert_eq!(back.words, rom.words, "{f:?}\n{text}");
                assert_eq!(text, back.to_text(f), "{f:?} output is not a fixed point");
            }
        }
    }

    #[test]
    fn rom_text_layout_is_fixed() {
        let r = Rom::new("x", 12, vec![0xabc, 1]);
        assert_eq!(r.to_hex(), "// x: 2 x 12 bits\nabc\n001\n");
        assert_eq!(r.to_coe().lines().skip(3).collect::<Vec<_>>(), ["abc,", "001;"]);
        assert!(r.to_mif().contains("\t0 : ABC;\n\t1 : 001;\nEND;\n"));
    }

    #[test]
    fn rom_parsers_accept_what_tools_write() {
        let hex = "/* hdr */ 0a // c\n@4 1_f\n 2\n";
        assert_eq!(parse_hex(hex).unwrap(), vec![0xa, 0, 0, 0, 0x1f, 2]);
        let mif = "% c % WIDTH = 8 ; DEPTH=6;\nADDRESS_RADIX=HEX;DATA_RADIX=UNS;\n\
                   CONTENT BEGIN\n [0..2] : 9; -- three nines\n 3 : 1 2 3;\nEND;";
        assert_eq!(parse_mif(mif).unwrap(), (8, vec![9, 9, 9, 1, 2, 3]));
        let coe = "; comment\nmemory_initialization_radix = 2;\nmemory_initialization_vector = 1 10,\n11;";
        assert_eq!(parse_coe(coe).unwrap(), vec![1, 2, 3]);
        assert!(matches!(parse_hex("zz"), Err(RomParseError::HexToken { token, .. }) if token == "zz"));
        assert_eq!(parse_hex("@1000000 0"), Err(RomParseError::Address(1 << 24)));
        assert_eq!(parse_hex("1 /* 2"), Err(RomParseError::UnterminatedComment));
        assert_eq!(parse_mif("WIDTH=4;DEPTH=1;CONTENT BEGIN 1 : 0; END;"), Err(RomParseError::MifAddress { addr: 1, depth: 1 }));
        assert_eq!(parse_mif("WIDTH=4;CONTENT BEGIN END;"), Err(RomParseError::Missing { format: "MIF", part: "DEPTH" }));
        assert_eq!(parse_coe("radix=2;"), Err(RomParseError::Field { format: "COE", field: "radix".into() }));
        assert_eq!(Rom::parse("x", 4, RomFormat::Hex, "1f"), Err(RomParseError::WordWidth { word: 0x1f, addr: 0, width: 4 }));
        let mif = Rom::new("m", 8, vec![1]).to_mif();
        assert_eq!(Rom::parse("m", 4, RomFormat::Mif, &mif), Err(RomParseError::MifWidth { declared: 8, expected: 4 }));
    }

    #[test]
    fn rom_addr_bits() {
        assert_eq!((addr_bits(0), addr_bits(1), addr_bits(2), addr_bits(3)), (1, 1, 1, 2));
        assert_eq!((addr_bits(1024), addr_bits(1025), addr_bits(3000)), (10, 11, 12));
    }
}
