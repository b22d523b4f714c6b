//! Where the engine's operations go (for [`super::schedule`]): each operation's class and
//! timing on the plan's units, and the modulo placement of the set-up program, by kind of unit
//! ([`modulo`]) or with every product on one tile ([`per_tile`]). Split from the schedule so
//! that neither file outgrows a reviewer's sitting; the schedule binds and costs what this
//! places.

use super::{Kind, MulUnit, Op, Plan, Program};

/// Clocks from a shift's start on a shared shifter to its value: the selected operands'
/// register, then the shift into the value's.
pub const SHIFT_PIPE: u32 = 2;

/// Clocks from a product's last pass to its value: the tile's input and output registers and
/// the accumulator.
pub const MUL_PIPE: u32 = 2;

/// What an operation occupies.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Class {
    Wire,
    Logic,
    Mul,
    Div,
    /// A shift by a value on one of the plan's shared barrel shifters.
    Shift,
}

pub(super) fn ceil(a: u32, b: u32) -> u32 {
    a.div_ceil(b)
}

pub(super) fn class(k: &Kind) -> Class {
    use Kind::*;
    match k {
        In(_) | Const(_) | Wire(_) | Shl(..) | Shr(..) | Rem(_) | Not(_) => Class::Wire,
        Mul(..) => Class::Mul,
        Div { .. } => Class::Div,
        _ => Class::Logic,
    }
}

/// The chunk pairs a product takes on a tile of `bits`: `(i, j)`, low chunks first, those
/// wholly above the kept bits left out.
pub(super) fn pairs(wa: u32, wb: u32, keep: u32, bits: u32) -> Vec<(u32, u32)> {
    let (ca, cb) = (ceil(wa, bits), ceil(wb, bits));
    (0..ca).flat_map(|i| (0..cb).map(move |j| (i, j))).filter(|&(i, j)| (i + j) * bits < keep).collect()
}

pub(super) fn timing(prog: &Program, op: &Op, plan: &Plan) -> (Class, u32, u32) {
    let c = class(&op.kind);
    match (c, op.kind) {
        (Class::Wire, _) => (c, 0, 0),
        // A shared shifter registers its selected operands, then shifts into the value's
        // register: the operand multiplexer and the shift are a clock each.
        (Class::Logic, Kind::ShlBy(..)) if plan.shifters > 0 => (Class::Shift, 1, SHIFT_PIPE),
        (Class::Logic, _) => (c, 0, 1),
        (Class::Mul, Kind::Mul(a, b)) => {
            let (wa, wb) = (prog.ops[a.0 as usize].w, prog.ops[b.0 as usize].w);
            match plan.mul {
                MulUnit::Tile { bits } => {
                    let p = pairs(wa, wb, op.w, bits).len() as u32;
                    (c, p, p + MUL_PIPE)
                }
                MulUnit::ShiftAdd { bits } => {
                    let p = ceil(wa.min(wb), bits);
                    (c, p, p + 1)
                }
            }
        }
        (_, Kind::Div { qb, .. }) => {
            let b = 1 + ceil(qb, plan.div_bits);
            (c, b, b)
        }
        _ => unreachable!("class of {:?}", op.kind),
    }
}

/// Where the scheduler placed the operations: each one's start clock, and a product's own
/// tile when the tiles were reserved one by one ([`per_tile`]).
pub(super) struct Placed {
    pub(super) start: Vec<u32>,
    pub(super) unit: Vec<Option<u32>>,
}

/// Places every operation at its earliest clock where a unit of its kind is free modulo `ii`
/// (the units counted by kind, not one by one); `None` if one does not fit within II clocks of
/// its earliest.
pub(super) fn modulo(prog: &Program, timing: &[(Class, u32, u32)], ii: u32, caps: impl Fn(Class) -> u32) -> Option<Vec<u32>> {
    let mut usage = [vec![0u32; ii as usize], vec![0u32; ii as usize], vec![0u32; ii as usize]];
    let mut start = vec![0u32; prog.ops.len()];
    let mut ready = vec![0u32; prog.ops.len()];
    for (o, op) in prog.ops.iter().enumerate() {
        let earliest = op.kind.args().iter().map(|a| ready[a.0 as usize]).max().unwrap_or(0);
        let (c, busy, lat) = timing[o];
        let t = match c {
            Class::Mul | Class::Div | Class::Shift => pooled(&mut usage[pool(c)], caps(c), earliest, busy)?,
            _ => earliest,
        };
        start[o] = t;
        ready[o] = t + lat;
    }
    Some(start)
}

/// The modulo table of a kind of unit counted by kind.
fn pool(c: Class) -> usize {
    match c {
        Class::Mul => 0,
        Class::Div => 1,
        _ => 2,
    }
}

/// The earliest clock from `earliest` on where `busy` more clocks of a kind of unit fit the
/// modulo table `usage` under `cap` units, taken; `None` if none within II clocks.
fn pooled(usage: &mut [u32], cap: u32, earliest: u32, busy: u32) -> Option<u32> {
    let ii = usage.len() as u32;
    let t = (earliest..earliest + ii).find(|&t| {
        let mut add = vec![0u32; ii as usize];
        (t..t + busy).for_each(|k| add[(k % ii) as usize] += 1);
        add.iter().zip(usage.iter()).all(|(a, b)| a + b <= cap)
    })?;
    (t..t + busy).for_each(|k| usage[(k % ii) as usize] += 1);
    Some(t)
}

/// Search nodes [`per_tile`] may visit for one plan before it settles for the tiles counted by
/// kind (the named plans need a few hundred).
const TILE_SEARCH_NODES: u32 = 20_000;

/// The schedule with every product on one tile for every triangle, at II `ii` and the least
/// latency from `from` up to `from + ii`; `None` if the search finds none within its budget.
///
/// Counting tiles by kind only ([`modulo`]) can place products whose clocks no static
/// assignment covers (at 8 tiles and II = 12 the set-up's did not), and the binding then rotates
/// products over tiles from triangle to triangle: the tiles' operand multiplexers select by
/// epoch as well as by phase (278 terms against 150, 1,625 LUT4 more, docs/fpga.md). Here each
/// tile has its own modulo table and a product takes one tile's clocks. A depth-first search
/// over the products' (clock, tile) choices, in program order, each at its earliest clock first
/// and on the tile left with the least free run around it (long runs stay for long products),
/// bounded by the latency: an operation whose start plus its shortest path to the results
/// exceeds the bound is cut. Divisions busier than II must alternate between dividers anyway:
/// they are counted by kind, as in [`modulo`], and bound afterwards ([`Schedule::bind`]).
pub(super) fn per_tile(prog: &Program, timing: &[(Class, u32, u32)], ii: u32, caps: &dyn Fn(Class) -> u32, from: u32) -> Option<Placed> {
    if timing.iter().any(|t| t.0 == Class::Mul && t.1 > ii) {
        return None;
    }
    let n = prog.ops.len();
    // The clocks from an operation's start to the last result, with no unit busy.
    let (mut tail, mut need) = (vec![0u32; n], vec![0u32; n]);
    for (o, op) in prog.ops.iter().enumerate().rev() {
        tail[o] = timing[o].2 + need[o];
        for a in op.kind.args() {
            need[a.0 as usize] = need[a.0 as usize].max(tail[o]);
        }
    }
    let mut budget = TILE_SEARCH_NODES;
    let empty = Search {
        start: vec![0; n],
        ready: vec![0; n],
        unit: vec![None; n],
        tiles: vec![vec![false; ii as usize]; caps(Class::Mul) as usize],
        pools: [vec![0; ii as usize], vec![0; ii as usize], vec![0; ii as usize]],
    };
    for bound in from..=from + ii {
        let ctx = Ctx { prog, timing, tail: &tail, ii, caps, bound };
        match ctx.go(0, empty.clone(), &mut budget) {
            Ok(Some(s)) => return Some(Placed { start: s.start, unit: s.unit }),
            Ok(None) => continue,
            Err(()) => return None,
        }
    }
    None
}

#[derive(Clone)]
struct Search {
    start: Vec<u32>,
    ready: Vec<u32>,
    unit: Vec<Option<u32>>,
    tiles: Vec<Vec<bool>>,
    pools: [Vec<u32>; 3],
}

struct Ctx<'a> {
    prog: &'a Program,
    timing: &'a [(Class, u32, u32)],
    tail: &'a [u32],
    ii: u32,
    caps: &'a dyn Fn(Class) -> u32,
    bound: u32,
}

impl Ctx<'_> {
    /// Places operations `o..` on `s`; `Err` when the budget runs out.
    fn go(&self, mut o: usize, mut s: Search, budget: &mut u32) -> Result<Option<Search>, ()> {
        let ii = self.ii;
        while o < self.prog.ops.len() {
            let earliest = self.prog.ops[o].kind.args().iter().map(|a| s.ready[a.0 as usize]).max().unwrap_or(0);
            let (c, busy, lat) = self.timing[o];
            if earliest + self.tail[o] > self.bound {
                return Ok(None);
            }
            let t = match c {
                Class::Mul => {
                    // Each clock in turn; of the tiles free there, each distinct table once.
                    for t in earliest..earliest + ii {
                        if t + self.tail[o] > self.bound {
                            break;
                        }
                        let at = |u: usize, k: u32| s.tiles[u][(k % ii) as usize];
                        let mut free: Vec<(u32, usize)> = Vec::new();
                        for u in 0..s.tiles.len() {
                            if (t..t + busy).all(|k| !at(u, k)) && !free.iter().any(|&(_, v)| s.tiles[v] == s.tiles[u]) {
                                let room = ii - busy;
                                let before = (1..=room).take_while(|&d| !at(u, t + ii - d)).count() as u32;
                                let after = (0..room - before).take_while(|&d| !at(u, t + busy + d)).count() as u32;
                                free.push((before + after, u));
                            }
                        }
                        free.sort();
                        for (_, u) in free {
                            *budget = budget.checked_sub(1).ok_or(())?;
                            let mut next = s.clone();
                            (t..t + busy).for_each(|k| next.tiles[u][(k % ii) as usize] = true);
                            (next.start[o], next.ready[o], next.unit[o]) = (t, t + lat, Some(u as u32));
                            if let Some(done) = self.go(o + 1, next, budget)? {
                                return Ok(Some(done));
                            }
                        }
                    }
                    return Ok(None);
                }
                Class::Div | Class::Shift => match pooled(&mut s.pools[pool(c)], (self.caps)(c), earliest, busy) {
                    Some(t) if t + self.tail[o] <= self.bound => t,
                    _ => return Ok(None),
                },
                _ => earliest,
            };
            (s.start[o], s.ready[o]) = (t, t + lat);
            o += 1;
        }
        Ok(Some(s))
    }
}
