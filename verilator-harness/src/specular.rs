//! Streams spans through the specular unit and checks every pixel three ways: bit-exact
//! against golden, within SPEC §4 of the f64 approximation `C cos^k(sqrt(n/k) delta)`, and,
//! along each span, never brighter where |theta| is larger.

use crate::cosim::{Mismatch, Pacer, Report, Stress, Traffic};
use crate::ffi::{to_port, ModelInfo, Rtl, SpecIn, SpecOut};
use golden::specular::reference::{approx, epicentre};
use golden::specular::setup::{norm, normalize, setup_span, SpanEnds, Vec3};
use golden::specular::{
    n_valid, theta_at, SpecularSpan, SpecularUnit, ABS_TOL, C_FRAC, INSIDE_REL, N_MAX, OUTSIDE_REL, THETA_FRAC,
};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use std::collections::VecDeque;

/// The specular unit under test, its golden twin and the driver's random source.
pub struct SpecularCosim {
    rtl: Rtl<SpecIn, SpecOut>,
    info: &'static ModelInfo<SpecIn, SpecOut>,
    unit: SpecularUnit,
    rng: StdRng,
    traffic: Traffic,
    stress: Stress,
    input: SpecIn,
    output: SpecOut,
}

const STALL_LIMIT: u64 = 10_000;

impl SpecularCosim {
    /// `unit` must be the configuration the model was generated from.
    pub fn new(info: &'static ModelInfo<SpecIn, SpecOut>, unit: SpecularUnit, seed: u64, traffic: Traffic) -> Self {
        let mut c = SpecularCosim {
            rtl: Rtl::new(info, seed),
            info,
            unit,
            rng: StdRng::seed_from_u64(seed),
            traffic,
            stress: Stress::NONE,
            input: SpecIn::default(),
            output: SpecOut::default(),
        };
        c.input.rst = 1;
        for _ in 0..2 {
            c.rtl.step_into(&c.input, &mut c.output);
        }
        c.input.rst = 0;
        c
    }

    pub fn info(&self) -> &'static ModelInfo<SpecIn, SpecOut> {
        self.info
    }

    /// Adds [`Stress`] to the traffic of every following [`SpecularCosim::stream`].
    pub fn set_stress(&mut self, stress: Stress) {
        self.stress = stress;
    }

    /// Streams `spans` (counted in `report.spans`; `report.failed` holds span indices). Panics,
    /// before the model sees anything, on a span its ports cannot take
    /// (see [`SpecularCosim::try_stream`]).
    pub fn stream(&mut self, spans: &[SpecularSpan], report: &mut Report) {
        if let Err(e) = self.try_stream(spans, report) {
            panic!("{}: {e}", self.info.tag);
        }
    }

    /// [`SpecularCosim::stream`], or an error naming the first span the ports cannot carry:
    /// `len` beyond the `in_len` port (XW + 1 bits) or `n` beyond the 10-bit `in_n` port. An n
    /// the port carries but outside 1..1000 is valid input (its pixels have `out_err = 1`).
    /// With [`Stress`] resets, a span cut by a reset owes no more pixels; a protocol monitor
    /// checks that a pixel offered and not taken stays, unchanged, and that `out_valid` is low
    /// in the first clock after a reset.
    pub fn try_stream(&mut self, spans: &[SpecularSpan], report: &mut Report) -> Result<(), String> {
        self.try_stream_with(spans, report, |_, _, _| {})
    }

    /// [`SpecularCosim::stream`], and `pixel` gets each checked output pixel that left the
    /// unit: its span's index, its pixel index `j` in the span and the outputs.
    pub fn stream_with(&mut self, spans: &[SpecularSpan], report: &mut Report, pixel: impl FnMut(usize, u32, &SpecOut)) {
        if let Err(e) = self.try_stream_with(spans, report, pixel) {
            panic!("{}: {e}", self.info.tag);
        }
    }

    /// [`SpecularCosim::try_stream`] with [`SpecularCosim::stream_with`]'s `pixel` callback.
    pub fn try_stream_with(
        &mut self,
        spans: &[SpecularSpan],
        report: &mut Report,
        mut pixel: impl FnMut(usize, u32, &SpecOut),
    ) -> Result<(), String> {
        let len_max = (1u32 << (self.info.cfg.xbits + 1)) - 1;
        for (k, s) in spans.iter().enumerate() {
            if s.len > len_max {
                return Err(format!("span {k} rejected: len = {} does not fit the {}-bit in_len port", s.len, self.info.cfg.xbits + 1));
            }
            if s.n as u32 >= 1 << golden::specular::N_BITS {
                return Err(format!("span {k} rejected: n = {} does not fit the {}-bit in_n port", s.n, golden::specular::N_BITS));
            }
        }
        let mut pacer = Pacer::new(self.traffic, self.stress);
        // (span, pixel j) of every pixel owed, in order.
        let mut expected: VecDeque<(usize, u32)> = VecDeque::new();
        let mut along: Vec<(u32, u16)> = Vec::new();
        let (mut next, mut offering, mut idle, mut drain) = (0, false, 0u64, 0);
        let (mut in_reset, mut held): (bool, Option<SpecOut>) = (false, None);
        loop {
            if next == spans.len() && expected.is_empty() {
                if drain == crate::cosim::DRAIN_CLOCKS {
                    break;
                }
                drain += 1;
            }
            if pacer.reset(&mut self.rng) {
                if !in_reset {
                    report.resets += 1;
                    let mut cut: Vec<usize> = expected.iter().map(|e| e.0).collect();
                    cut.dedup();
                    report.cut_spans += cut.len() as u64;
                    expected.clear();
                    along.clear();
                }
                in_reset = true;
                held = None;
                self.input.rst = 1;
                self.input.in_valid = offering as u8;
                self.input.out_ready = pacer.ready(&mut self.rng) as u8;
                self.rtl.step_into(&self.input, &mut self.output);
                self.input.rst = 0;
                report.cycles += 1;
                idle = 0;
                continue;
            }
            if !offering && next < spans.len() {
                offering = pacer.offer(&mut self.rng);
                if offering {
                    let s = &spans[next];
                    self.input.in_c = s.c as u32;
                    self.input.in_n = s.n as u32;
                    self.input.in_theta0 = to_port(s.theta0 as i64, 32);
                    self.input.in_dtheta = to_port(s.dtheta as i64, 32);
                    self.input.in_len = s.len;
                }
            }
            self.input.in_valid = offering as u8;
            self.input.out_ready = pacer.ready(&mut self.rng) as u8;
            self.rtl.step_into(&self.input, &mut self.output);
            report.cycles += 1;
            if std::mem::take(&mut in_reset) && self.output.out_valid != 0 {
                report.mismatch(Mismatch {
                    triangle: None,
                    context: format!("clock {}", report.cycles),
                    what: "out_valid high in the first clock after a reset".into(),
                });
            }
            if let Some(h) = held.take() {
                let o = &self.output;
                if o.out_valid != 1 || (o.out_spec, o.out_last, o.out_err) != (h.out_spec, h.out_last, h.out_err) {
                    report.mismatch(Mismatch {
                        triangle: None,
                        context: format!("clock {}", report.cycles),
                        what: format!("pixel {h:?} dropped or changed while waiting for out_ready: now {o:?}"),
                    });
                }
            }
            let mut progress = false;
            if self.output.out_valid == 1 && self.input.out_ready == 1 {
                progress = true;
                match expected.pop_front() {
                    Some((k, j)) => {
                        self.check(k, &spans[k], j, report, &mut along);
                        pixel(k, j, &self.output);
                        if j + 1 == spans[k].len {
                            check_monotone(k, &mut along, report);
                        }
                    }
                    None => report.mismatch(Mismatch {
                        triangle: None,
                        context: format!("clock {}", report.cycles),
                        what: "pixel with no span outstanding".into(),
                    }),
                }
            } else if self.output.out_valid == 1 {
                held = Some(self.output);
            }
            if offering && self.output.in_ready == 1 {
                progress = true;
                expected.extend((0..spans[next].len).map(|j| (next, j)));
                report.spans += 1;
                next += 1;
                offering = false;
                pacer.accepted(&mut self.rng);
            }
            idle = if progress { 0 } else { idle + 1 };
            if idle > STALL_LIMIT {
                report.mismatch(Mismatch {
                    triangle: expected.front().map(|e| e.0),
                    context: "stream".into(),
                    what: format!("no transfer for {STALL_LIMIT} clocks; {} pixels still expected", expected.len()),
                });
                return Ok(());
            }
        }
        Ok(())
    }

    fn check(&self, k: usize, s: &SpecularSpan, j: u32, report: &mut Report, along: &mut Vec<(u32, u16)>) {
        let out = &self.output;
        let (spec, err) = self.unit.pixel(s.c, s.n, s.theta0, s.dtheta, j);
        let last = j + 1 == s.len;
        let mut problems = Vec::new();
        if (out.out_spec, out.out_err == 1, out.out_last == 1) != (spec, err, last) {
            problems.push(format!(
                "expected spec {spec} err {} last {}, got spec {} err {} last {}",
                err as u8, last as u8, out.out_spec, out.out_err, out.out_last
            ));
        }
        let theta = theta_at(s.theta0, s.dtheta, j);
        if let Some(k_n) = self.unit.plan().decoder.k_of(s.n as u32).filter(|_| n_valid(s.n as u32)) {
            let scale = (1u32 << C_FRAC) as f64;
            let (c, got) = (s.c as f64 / scale, out.out_spec as f64 / scale);
            let delta = theta.unsigned_abs() as f64 / (1u64 << THETA_FRAC) as f64;
            let want = approx(c, s.n as u32, k_n, delta);
            let inside = delta <= epicentre(s.n as u32);
            let tol = if inside { INSIDE_REL * want } else { OUTSIDE_REL * c } + ABS_TOL;
            if (got - want).abs() > tol {
                let place = if inside { "inside" } else { "outside" };
                problems.push(format!("{got:.5} is {:.5} from approx {want:.5} {place} the epicentre (bound {tol:.5})", (got - want).abs()));
            }
        }
        along.push((theta.unsigned_abs(), out.out_spec));
        report.pixels += 1;
        if !problems.is_empty() {
            report.mismatch(Mismatch {
                triangle: Some(k),
                context: format!("span {k} (c {} n {} theta0 {} dtheta {} len {}), pixel {j}", s.c, s.n, s.theta0, s.dtheta, s.len),
                what: problems.join("; "),
            });
        }
    }
}

/// Along a span the output never grows as |theta| grows.
fn check_monotone(k: usize, along: &mut Vec<(u32, u16)>, report: &mut Report) {
    along.sort_unstable();
    if let Some(w) = along.windows(2).find(|w| w[1].1 > w[0].1) {
        report.mismatch(Mismatch {
            triangle: Some(k),
            context: format!("span {k}"),
            what: format!("output grows with |theta|: {} at |theta| {}, {} at {}", w[0].1, w[0].0, w[1].1, w[1].0),
        });
    }
    along.clear();
}

/// The shininess of a random span: all four default k ranges, their boundaries, and invalid n.
pub fn random_n(rng: &mut impl Rng) -> u16 {
    match rng.gen_range(0..20) {
        0..=7 => rng.gen_range(7..=N_MAX as u16),
        8..=10 => rng.gen_range(3..=6),
        11 => 1,
        12 => 2,
        13..=16 => [1, 2, 3, 6, 7, 1000][rng.gen_range(0..6)],
        17 => [0, 1001, 1023][rng.gen_range(0..3)],
        _ => rng.gen_range(1001..=1023),
    }
}

/// Uniform on the sphere: rejection from the cube, away from the centre.
fn unit_vector(rng: &mut impl Rng) -> Vec3 {
    loop {
        let v: Vec3 = [rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0)];
        if (0.1..=1.0).contains(&norm(v)) {
            return normalize(v).expect("not near zero");
        }
    }
}

fn near(rng: &mut impl Rng, v: Vec3, spread: f64) -> Vec3 {
    let u = unit_vector(rng);
    [v[0] + spread * u[0], v[1] + spread * u[1], v[2] + spread * u[2]]
}

/// A random span as the host would set it up: normals and half-vectors at both ends (mostly a
/// highlight crossing the span, sometimes anything at all, including degenerate pairs).
pub fn random_span(rng: &mut impl Rng, max_len: u32) -> SpecularSpan {
    let n = random_n(rng);
    let n1 = unit_vector(rng);
    let ends = match rng.gen_range(0..10) {
        0 => SpanEnds { n1, h1: unit_vector(rng), n2: unit_vector(rng), h2: unit_vector(rng) },
        1 => SpanEnds { n1, h1: n1, n2: n1, h2: n1 },
        2 => SpanEnds { n1, h1: near(rng, n1, 0.3), n2: [-n1[0], -n1[1], -n1[2]], h2: near(rng, n1, 0.3) },
        _ => {
            let spread = rng.gen_range(0.01..0.8);
            SpanEnds { n1, h1: near(rng, n1, spread), n2: near(rng, n1, spread), h2: near(rng, n1, spread) }
        }
    };
    let l = rng.gen_range(0..max_len.min(400));
    let il_ks = rng.gen_range(0.5..300.0);
    setup_span(&ends, il_ks, 1.0, n, l).port
}
