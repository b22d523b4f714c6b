//! The decoder n -> table: which `cos^k` curve approximates `cos^n`.

use super::contract::{n_valid, K_MAX, N_MAX, N_MIN};
use super::reference::approx_error;
use serde::{Deserialize, Serialize};
use std::fmt;

/// A k-set and the table each valid n uses. Tables are numbered in ascending k; the number
/// is the `sel` field of the n-table ROM word. Serialized as the k-set and its n ranges.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(into = "DecoderRepr", try_from = "DecoderRepr")]
pub struct Decoder {
    ks: Vec<u32>,
    /// `table[n - 1]` for n in 1..=1000.
    table: Vec<u8>,
}

/// A maximal run of consecutive n on one table (what the manifest lists as "k ranges").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct KRange {
    pub table: u32,
    pub k: u32,
    pub n_lo: u32,
    pub n_hi: u32,
}

/// The serialized form of a [`Decoder`].
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct DecoderRepr {
    pub ks: Vec<u32>,
    pub ranges: Vec<KRange>,
}

impl From<Decoder> for DecoderRepr {
    fn from(d: Decoder) -> DecoderRepr {
        DecoderRepr { ranges: d.ranges(), ks: d.ks }
    }
}

/// A k set the unit cannot hold ([`check_k_set`]).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum KSetError {
    #[error("the BRDF k set is empty")]
    Empty,
    #[error("{0} BRDF tables is more than the 16 this unit supports")]
    TooMany(usize),
    #[error("BRDF k = {0} is outside 1..{K_MAX}")]
    OutOfRange(u32),
    #[error("BRDF k set {0:?} is not strictly ascending")]
    NotAscending(Vec<u32>),
}

/// A decoder that does not put every valid n on one of its tables.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum DecoderError {
    #[error(transparent)]
    KSet(#[from] KSetError),
    /// A serialized range that does not start where the last ended, or names another k.
    #[error("decoder range {range:?} does not continue from n = {next} on the k set {ks:?}")]
    Gap { range: KRange, next: u32, ks: Vec<u32> },
    #[error("decoder ranges end at n = {end}, not {N_MAX}")]
    Short { end: u32 },
    #[error("n = {n} assigned to table {table} of only {tables}")]
    NoTable { n: u32, table: usize, tables: usize },
}

impl TryFrom<DecoderRepr> for Decoder {
    type Error = DecoderError;
    fn try_from(r: DecoderRepr) -> Result<Decoder, DecoderError> {
        let mut next = N_MIN;
        for g in &r.ranges {
            if g.n_lo != next || g.n_hi < g.n_lo || r.ks.get(g.table as usize) != Some(&g.k) {
                return Err(DecoderError::Gap { range: *g, next, ks: r.ks.clone() });
            }
            next = g.n_hi + 1;
        }
        if next != N_MAX + 1 {
            return Err(DecoderError::Short { end: next - 1 });
        }
        let at = |n: u32| r.ranges.iter().find(|g| g.n_lo <= n && n <= g.n_hi).map_or(0, |g| g.table as usize);
        Decoder::from_fn(&r.ks, at)
    }
}

/// A k-set must be strictly ascending, non-empty, within 1..=64, and small enough that the
/// select field stays a few bits.
pub fn check_k_set(ks: &[u32]) -> Result<(), KSetError> {
    if ks.is_empty() {
        return Err(KSetError::Empty);
    }
    if ks.len() > 16 {
        return Err(KSetError::TooMany(ks.len()));
    }
    if let Some(&k) = ks.iter().find(|&&k| k == 0 || k > K_MAX) {
        return Err(KSetError::OutOfRange(k));
    }
    if ks.windows(2).any(|w| w[0] >= w[1]) {
        return Err(KSetError::NotAscending(ks.to_vec()));
    }
    Ok(())
}

impl Decoder {
    /// The patent's decoder (fig. 13): n = 1 -> cos, 2 -> cos^2, 3..6 -> cos^4, 7..1000 -> cos^16.
    pub fn patent() -> Decoder {
        let table = (N_MIN..=N_MAX)
            .map(|n| match n {
                1 => 0,
                2 => 1,
                3..=6 => 2,
                _ => 3,
            })
            .collect();
        Decoder { ks: vec![1, 2, 4, 16], table }
    }

    /// Each n takes the table whose approximation error over its epicentre is least
    /// (a tie goes to the smaller k). For {1, 2, 4, 16} this is exactly the patent's decoder.
    pub fn least_error(ks: &[u32]) -> Result<Decoder, KSetError> {
        check_k_set(ks)?;
        let table = (N_MIN..=N_MAX)
            .map(|n| {
                let mut best = 0;
                for (t, &k) in ks.iter().enumerate() {
                    if approx_error(n, k) < approx_error(n, ks[best]) {
                        best = t;
                    }
                }
                best as u8
            })
            .collect();
        Ok(Decoder { ks: ks.to_vec(), table })
    }

    /// A decoder from an explicit assignment `table_of(n)` for n in 1..=1000.
    pub fn from_fn(ks: &[u32], table_of: impl Fn(u32) -> usize) -> Result<Decoder, DecoderError> {
        check_k_set(ks)?;
        let mut table = Vec::with_capacity(N_MAX as usize);
        for n in N_MIN..=N_MAX {
            let t = table_of(n);
            if t >= ks.len() {
                return Err(DecoderError::NoTable { n, table: t, tables: ks.len() });
            }
            table.push(t as u8);
        }
        Ok(Decoder { ks: ks.to_vec(), table })
    }

    pub fn ks(&self) -> &[u32] {
        &self.ks
    }
    pub fn tables(&self) -> usize {
        self.ks.len()
    }
    /// Table number of n, `None` for an invalid n.
    pub fn table_of(&self, n: u32) -> Option<usize> {
        n_valid(n).then(|| self.table[(n - 1) as usize] as usize)
    }
    pub fn k_of(&self, n: u32) -> Option<u32> {
        self.table_of(n).map(|t| self.ks[t])
    }
    /// The n that use table t, ascending.
    pub fn ns_of(&self, t: usize) -> impl Iterator<Item = u32> + '_ {
        (N_MIN..=N_MAX).filter(move |&n| self.table[(n - 1) as usize] as usize == t)
    }
    /// f64 approximation error of n's table over n's epicentre.
    pub fn error_of(&self, n: u32) -> Option<f64> {
        self.k_of(n).map(|k| approx_error(n, k))
    }
    /// Worst approximation error over all n, and the n where it occurs.
    pub fn max_error(&self) -> (f64, u32) {
        (N_MIN..=N_MAX).map(|n| (self.error_of(n).unwrap_or(0.0), n)).fold((0.0, 0), |a, b| if b.0 > a.0 { b } else { a })
    }

    pub fn ranges(&self) -> Vec<KRange> {
        let mut out: Vec<KRange> = Vec::new();
        for n in N_MIN..=N_MAX {
            let t = self.table[(n - 1) as usize] as u32;
            match out.last_mut() {
                Some(r) if r.table == t => r.n_hi = n,
                _ => out.push(KRange { table: t, k: self.ks[t as usize], n_lo: n, n_hi: n }),
            }
        }
        out
    }
}

impl fmt::Display for Decoder {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let parts: Vec<String> = self
            .ranges()
            .iter()
            .map(|r| {
                let ns = if r.n_lo == r.n_hi { r.n_lo.to_string() } else { format!("{}..{}", r.n_lo, r.n_hi) };
                format!("n={ns}->k={}", r.k)
            })
            .collect();
        f.write_str(&parts.join(", "))
    }
}

/// The `--brdf-k` option: an explicit k list (`1,2,4,16`, the default) or `auto` with a
/// target for the max relative approximation error inside the epicentre
/// (`auto:0.5%` or `auto:0.005`; bare `auto` means the patent's 1%).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BrdfK {
    List(Vec<u32>),
    Auto { max_err: f64 },
}

impl Default for BrdfK {
    fn default() -> Self {
        BrdfK::List(vec![1, 2, 4, 16])
    }
}

/// A relative-error target (`--max-rel-error`, `--brdf-k auto:T`) that does not read.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum TargetError {
    #[error("'{0}' is not a number")]
    NotANumber(String),
    #[error("'{0}' is not a relative error between 0 and 1 (or 0% and 100%)")]
    Range(String),
}

/// A relative error written as a fraction (`0.01`) or a percentage (`1%`), strictly between 0
/// and 1: `--max-rel-error` and the target of `--brdf-k auto:T`.
pub fn parse_rel_error(s: &str) -> Result<f64, TargetError> {
    let (num, per) = match s.strip_suffix('%') {
        Some(n) => (n, 100.0),
        None => (s, 1.0),
    };
    let e = num.trim().parse::<f64>().map_err(|_| TargetError::NotANumber(s.to_string()))? / per;
    if e.is_finite() && e > 0.0 && e < 1.0 {
        Ok(e)
    } else {
        Err(TargetError::Range(s.to_string()))
    }
}

/// A `--brdf-k` value [`BrdfK`] does not read.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum BrdfKError {
    #[error(transparent)]
    Target(#[from] TargetError),
    #[error("bad k '{k}' in '{list}'")]
    K { k: String, list: String },
    #[error(transparent)]
    KSet(#[from] KSetError),
}

impl std::str::FromStr for BrdfK {
    type Err = BrdfKError;
    fn from_str(s: &str) -> Result<Self, BrdfKError> {
        let s = s.trim();
        if let Some(rest) = s.strip_prefix("auto") {
            let e = rest.trim_start_matches([':', '=']).trim();
            let max_err = if e.is_empty() { 0.01 } else { parse_rel_error(e)? };
            return Ok(BrdfK::Auto { max_err });
        }
        let ks = s
            .split(',')
            .map(|t| t.trim().parse::<u32>().map_err(|_| BrdfKError::K { k: t.trim().to_string(), list: s.to_string() }))
            .collect::<Result<Vec<_>, _>>()?;
        check_k_set(&ks)?;
        Ok(BrdfK::List(ks))
    }
}

impl fmt::Display for BrdfK {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BrdfK::List(ks) => {
                let v: Vec<String> = ks.iter().map(u32::to_string).collect();
                f.write_str(&v.join(","))
            }
            BrdfK::Auto { max_err } => write!(f, "auto:{}%", max_err * 100.0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specular_decoder_patent_is_least_error_for_its_set() {
        assert_eq!(Decoder::least_error(&[1, 2, 4, 16]).unwrap(), Decoder::patent());
        let r = Decoder::patent().ranges();
        let spans: Vec<_> = r.iter().map(|r| (r.k, r.n_lo, r.n_hi)).collect();
        assert_eq!(spans, [(1, 1, 1), (2, 2, 2), (4, 3, 6), (16, 7, 1000)]);
        assert_eq!(Decoder::patent().to_string(), "n=1->k=1, n=2->k=2, n=3..6->k=4, n=7..1000->k=16");
        assert_eq!(Decoder::patent().k_of(0), None);
        assert_eq!(Decoder::patent().k_of(1001), None);
    }

    #[test]
    fn specular_decoder_reproduces_spec_figures() {
        let d = Decoder::patent();
        let (worst, n) = d.max_error();
        assert_eq!(n, 3);
        assert!((worst - 0.0109).abs() < 0.00005, "{worst}");
        let above = |m: u32| (m..=N_MAX).map(|n| d.error_of(n).unwrap()).fold(0.0, f64::max);
        assert!((above(6) - 0.0088).abs() < 0.00005, "{}", above(6));
        assert!(above(8) <= 0.00602 && above(8) > 0.0059, "{}", above(8));
        // The prototype's single cos^2 curve, over the n it was meant for (2..1000): 4.7%.
        let proto = (2..=N_MAX).map(|n| approx_error(n, 2)).fold(0.0, f64::max);
        assert!((proto - 0.047).abs() < 0.0005, "{proto}");
        assert!(approx_error(1, 2) > 0.089, "n = 1 on cos^2 is worse still");
    }

    #[test]
    fn specular_decoder_error_is_unimodal_in_k() {
        // The auto search relies on it: the best k for n is a neighbour of n in the set.
        for n in N_MIN..=N_MAX {
            for k in 1..K_MAX {
                let (a, b) = (approx_error(n, k), approx_error(n, k + 1));
                if k < n {
                    assert!(b <= a, "n={n} k={k}");
                }
                if k >= n {
                    assert!(b >= a, "n={n} k={k}");
                }
            }
        }
    }

    #[test]
    fn specular_decoder_serial_form_round_trips() {
        for d in [Decoder::patent(), Decoder::least_error(&[1, 3, 9, 40, 64]).unwrap()] {
            let r = DecoderRepr::from(d.clone());
            assert_eq!(Decoder::try_from(r.clone()).unwrap(), d);
            let mut gap = r.clone();
            let lost = gap.ranges.remove(1);
            let next = gap.ranges[1];
            assert_eq!(Decoder::try_from(gap), Err(DecoderError::Gap { range: next, next: lost.n_lo, ks: r.ks.clone() }));
            let mut short = r;
            short.ranges.last_mut().unwrap().n_hi -= 1;
            assert_eq!(Decoder::try_from(short), Err(DecoderError::Short { end: N_MAX - 1 }));
        }
    }

    #[test]
    fn specular_decoder_parses_brdf_k() {
        assert_eq!("1,2,4,16".parse::<BrdfK>().unwrap(), BrdfK::default());
        assert_eq!(" 3 , 9".parse::<BrdfK>().unwrap(), BrdfK::List(vec![3, 9]));
        assert_eq!("auto".parse::<BrdfK>().unwrap(), BrdfK::Auto { max_err: 0.01 });
        assert_eq!("auto:0.5%".parse::<BrdfK>().unwrap(), BrdfK::Auto { max_err: 0.005 });
        assert_eq!("auto=0.002".parse::<BrdfK>().unwrap(), BrdfK::Auto { max_err: 0.002 });
        let k = |k: &str, list: &str| BrdfKError::K { k: k.into(), list: list.into() };
        let cases = [
            ("", k("", "")),
            ("1,1", KSetError::NotAscending(vec![1, 1]).into()),
            ("4,2", KSetError::NotAscending(vec![4, 2]).into()),
            ("0,3", KSetError::OutOfRange(0).into()),
            ("65", KSetError::OutOfRange(65).into()),
            ("1,x", k("x", "1,x")),
            ("auto:0", TargetError::Range("0".into()).into()),
            ("auto:150%", TargetError::Range("150%".into()).into()),
            ("auto:lots", TargetError::NotANumber("lots".into()).into()),
            ("auto:inf", TargetError::Range("inf".into()).into()),
        ];
        for (bad, want) in cases {
            assert_eq!(bad.parse::<BrdfK>(), Err(want), "{bad}");
        }
        assert_eq!(Decoder::from_fn(&[1, 2], |n| n as usize % 3), Err(DecoderError::NoTable { n: 2, table: 2, tables: 2 }));
        assert_eq!(check_k_set(&(1..=17).collect::<Vec<_>>()), Err(KSetError::TooMany(17)));
        assert_eq!(check_k_set(&[]), Err(KSetError::Empty));
        assert_eq!(BrdfK::Auto { max_err: 0.005 }.to_string(), "auto:0.5%");
        assert_eq!(BrdfK::default().to_string(), "1,2,4,16");
    }
}
