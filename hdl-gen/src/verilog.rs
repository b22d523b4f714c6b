//! A small typed writer for Verilog-2005: modules, ports, wires, registers, assigns, clocked
//! always blocks, instances and generate loops. Expressions stay strings — the structure is
//! what must be right, and every emitter goes through this one printer so the output has one
//! style: ANSI ports, two-space indent, one declaration per line.

use std::fmt::Write;

#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Dir {
    Input,
    Output,
}

/// A port. `format` is the fixed-point format, printed beside the port and in the manifest.
#[derive(Clone, Debug)]
pub struct Port {
    pub name: String,
    pub dir: Dir,
    pub width: u32,
    pub signed: bool,
    /// Driven from a register (`output reg`).
    pub reg: bool,
    /// Declared with a range even at width 1, so lanes can be indexed when P = 1.
    pub vector: bool,
    pub format: String,
    pub doc: String,
    /// Verilog-2005 attribute instances printed before the declaration, one per line, each the
    /// text between `(*` and `*)`: vendor tools read interfaces from them (`--bus axis`).
    pub attrs: Vec<String>,
    /// A parameterised module's port: its width as a parameter expression, printed `[w-1:0]`;
    /// `width` is then its width at the parameters' defaults (what the manifest states).
    pub param_width: Option<String>,
}

impl Port {
    pub fn input(name: &str, width: u32, format: &str, doc: &str) -> Port {
        Port {
            name: name.into(),
            dir: Dir::Input,
            width,
            signed: false,
            reg: false,
            vector: false,
            format: format.into(),
            doc: doc.into(),
            attrs: Vec::new(),
            param_width: None,
        }
    }
    pub fn output(name: &str, width: u32, format: &str, doc: &str) -> Port {
        Port { dir: Dir::Output, ..Port::input(name, width, format, doc) }
    }
    pub fn signed(mut self) -> Port {
        self.signed = true;
        self
    }
    pub fn reg(mut self) -> Port {
        self.reg = true;
        self
    }
    pub fn vector(mut self) -> Port {
        self.vector = true;
        self
    }
    /// Declares the port `[width-1:0]`, `width` a parameter expression; `self.width` stays its width at the parameters' defaults.
    pub fn param_width(mut self, width: &str) -> Port {
        self.param_width = Some(width.into());
        self
    }
    /// Adds the attribute instance `(* attr *)` before the declaration.
    pub fn attr(mut self, attr: impl Into<String>) -> Port {
        self.attrs.push(attr.into());
        self
    }
}

/// Statements inside a clocked always block (and, for testbenches, an `initial` block).
#[derive(Clone, Debug)]
pub enum Stmt {
    /// Non-blocking assignment.
    Set(String, String),
    If(String, Vec<Stmt>, Vec<Stmt>),
    Comment(String),
    /// Blocking assignment `lhs = rhs;`: testbenches, and the variables of an [`Item::Comb`].
    Blocking(String, String),
    /// Testbench only: a system task call such as `$display("...", x)`, printed with its `;`.
    Call(String),
    /// Testbench only: `#n;`.
    Delay(u32),
    /// Testbench only: `forever begin ... end`.
    Forever(Vec<Stmt>),
    /// `for (var = 0; var < count; var = var + 1) begin ... end` over an [`Item::Integer`], in a
    /// combinational block ([`Item::Comb`]): the steps of a chain written once.
    For {
        var: String,
        count: String,
        body: Vec<Stmt>,
    },
    /// Formal only (inside [`Item::Formal`]): an immediate `assert(cond);`.
    Assert(String),
    /// Formal only: an immediate `assume(cond);`, a rule the environment is held to.
    Assume(String),
    /// Formal only: an immediate `cover(cond);`, a state the proof must show reachable
    /// (`scripts/prove` runs a cover search), so a proof that holds only vacuously fails.
    Cover(String),
    /// Formal only: `label: stmt`, given to every assert and cover when the block renders.
    Labelled(String, Box<Stmt>),
    /// `case (sel) label: ...; default: ...; endcase`: a table (synthesis maps a registered one
    /// to block RAM, Yosys's `proc_rom`), one arm a line.
    Case {
        sel: String,
        arms: Vec<(String, Vec<Stmt>)>,
        default: Vec<Stmt>,
    },
}

pub fn set(lhs: impl Into<String>, rhs: impl Into<String>) -> Stmt {
    Stmt::Set(lhs.into(), rhs.into())
}

#[derive(Clone, Debug)]
pub enum Item {
    Blank,
    Comment(String),
    /// `wire [w-1:0] name;` or, with a value, `wire [w-1:0] name = value;`.
    Wire {
        name: String,
        width: u32,
        signed: bool,
        value: Option<String>,
    },
    /// A lane bus driven elsewhere, declared with a range even at width 1.
    Bus {
        name: String,
        width: u32,
    },
    Reg {
        name: String,
        width: u32,
        signed: bool,
    },
    /// `localparam [w-1:0] NAME = value;` (width 0: unsized).
    Localparam {
        name: String,
        width: u32,
        value: String,
    },
    /// A parameterised module's declaration, its width a parameter expression:
    /// `wire|reg [width-1:0] name [= value];` or `localparam [width-1:0] name = value;`.
    Sized {
        kind: Kind,
        name: String,
        width: String,
        value: Option<String>,
    },
    /// `integer name;`: the variable of a [`Stmt::For`].
    Integer(String),
    Assign(String, String),
    /// `always @(posedge clk)`.
    Always(Vec<Stmt>),
    Instance {
        module: String,
        name: String,
        params: Vec<(String, String)>,
        conns: Vec<(String, String)>,
    },
    /// `for (var = 0; var < count; var = var + 1) begin : label ... end` in a generate region.
    ForGenerate {
        var: String,
        count: u32,
        label: String,
        body: Vec<Item>,
    },
    /// `if (cond) begin : label ... end else begin : label2 ... end` inside a generate region.
    IfGenerate {
        cond: String,
        then: (String, Vec<Item>),
        els: (String, Vec<Item>),
    },
    /// A ROM load: `initial $readmemh(file, mem);` — the only `initial` SPEC allows.
    ReadMemH {
        file: String,
        mem: String,
    },
    /// `reg [w-1:0] name [0:depth-1];`, after `(* no_rw_check *)` if never read where written that clock.
    Memory {
        name: String,
        width: u32,
        depth: u32,
        no_rw_check: bool,
    },
    /// Testbench only (SPEC §3 allows no `initial` in the modules): `initial begin ... end`.
    Initial(Vec<Stmt>),
    /// `always @(*) begin ... end`: combinational checks of the formal properties.
    Comb(Vec<Stmt>),
    /// `always @(*) name = {...};`: a bus of lanes (`lanes[0]` least significant) assembled by one process. See [`gather`].
    Gather {
        name: String,
        lanes: Vec<String>,
    },
    /// Formal only: `reg [w-1:0] name = value;`, a register whose first value the solver
    /// knows (the `f_past` flags; the product RTL has no initial values).
    RegInit {
        name: String,
        width: u32,
        value: String,
    },
    /// `` `ifdef FORMAL `` ... `` `endif ``: properties read by `read_verilog -formal` (Yosys
    /// defines FORMAL), invisible to every other tool, so the product stays Verilog-2005.
    Formal(Vec<Item>),
    /// Formal only: `` `ifdef name `` `then` `` `else `` `els` `` `endif ``, a choice a proof
    /// script makes with `read_verilog -Dname` (e.g. a lemma asserted in its own proof and assumed in the proof that uses it).
    IfDef {
        name: String,
        then: Vec<Item>,
        els: Vec<Item>,
    },
}

/// What an [`Item::Sized`] declares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Wire,
    Reg,
    Localparam,
}

/// `kind [width-1:0] name [= value];`, `width` a parameter expression.
pub fn sized(kind: Kind, name: &str, width: &str, value: Option<String>) -> Item {
    Item::Sized { kind, name: name.into(), width: width.into(), value }
}

pub fn wire(name: &str, width: u32, value: impl Into<String>) -> Item {
    Item::Wire { name: name.into(), width, signed: false, value: Some(value.into()) }
}
pub fn swire(name: &str, width: u32, value: impl Into<String>) -> Item {
    Item::Wire { name: name.into(), width, signed: true, value: Some(value.into()) }
}
/// A wire driven elsewhere (by `assign`s or an instance).
pub fn net(name: &str, width: u32) -> Item {
    Item::Wire { name: name.into(), width, signed: false, value: None }
}
/// A lane bus driven elsewhere, indexable at any width.
pub fn bus(name: &str, width: u32) -> Item {
    Item::Bus { name: name.into(), width }
}
pub fn reg(name: &str, width: u32) -> Item {
    Item::Reg { name: name.into(), width, signed: false }
}
pub fn sreg(name: &str, width: u32) -> Item {
    Item::Reg { name: name.into(), width, signed: true }
}
pub fn assign(lhs: impl Into<String>, rhs: impl Into<String>) -> Item {
    Item::Assign(lhs.into(), rhs.into())
}
pub fn comment(text: impl Into<String>) -> Item {
    Item::Comment(text.into())
}

/// The bus `name` (a `reg`) assembled from `lanes`, least significant first, by one
/// `always @(*)` concatenation, where `assign name[k*w +: w] = ...` would drive it lane by lane.
///
/// A bus driven lane by lane changes once per lane, and Icarus Verilog hands the whole bus to
/// every reader at each change: P lanes changing in one clock cost P times the bus (O(P^2) bit
/// copies, O(P^3) when P readers each take a lane). One process runs once per clock however
/// many of its inputs change, so the bus changes once. Icarus builds a concatenation left to
/// right, copying what it has built at each step; rows of eight lanes, nested, divide that
/// copying by about eight (a few per cent of a P = 256 clock). Synthesis and Verilator see the same wires either way.
pub fn gather(name: &str, lanes: Vec<String>) -> Item {
    assert!(!lanes.is_empty(), "gather {name} from no lanes");
    Item::Gather { name: name.into(), lanes }
}

/// Lanes per row of an [`Item::Gather`] concatenation.
const GATHER_ROW: usize = 8;

#[derive(Clone, Debug)]
pub struct Param {
    pub name: String,
    pub value: String,
    pub doc: String,
}

#[derive(Clone, Debug)]
pub struct Module {
    pub name: String,
    /// Lines of the header comment (configuration, formats, structure).
    pub header: Vec<String>,
    pub params: Vec<Param>,
    pub ports: Vec<Port>,
    pub body: Vec<Item>,
}

/// `[w-1:0] ` or nothing for one bit.
fn range(width: u32) -> String {
    vrange(width, false)
}

fn vrange(width: u32, vector: bool) -> String {
    if width == 1 && !vector {
        String::new()
    } else {
        format!("[{}:0] ", width - 1)
    }
}

fn sign(signed: bool) -> &'static str {
    if signed {
        "signed "
    } else {
        ""
    }
}

/// `{{n{x[msb]}}, x}`: sign-extends `x` (of `from` bits) to `to` bits.
pub fn sext(x: &str, from: u32, to: u32) -> String {
    assert!(to >= from, "sext narrows {x} from {from} to {to}");
    if to == from {
        x.to_string()
    } else if from == 1 {
        format!("{{{to}{{{x}}}}}")
    } else {
        format!("{{{{{}{{{x}[{}]}}}}, {x}}}", to - from, from - 1)
    }
}

/// `{{n{1'b0}}, x}`: zero-extends.
pub fn zext(x: &str, from: u32, to: u32) -> String {
    assert!(to >= from, "zext narrows {x} from {from} to {to}");
    if to == from {
        x.to_string()
    } else {
        format!("{{{}'d0, {x}}}", to - from)
    }
}

/// Bit `b` of a `width`-bit net: a one-bit net cannot be bit-selected in Verilog-2005.
pub fn bit(x: &str, width: u32, b: u32) -> String {
    if width == 1 {
        x.to_string()
    } else {
        format!("{x}[{b}]")
    }
}

/// A sized decimal constant.
pub fn lit(width: u32, value: u64) -> String {
    format!("{width}'d{value}")
}

impl Module {
    /// A formal-only module (a proof's reference), for appending to a product file: inside
    /// `` `ifdef FORMAL ``, so no other tool sees it.
    pub fn render_formal(&self) -> String {
        format!("\n`ifdef FORMAL\n{}`endif\n", self.render())
    }

    pub fn render(&self) -> String {
        let mut o = String::new();
        for line in &self.header {
            if line.is_empty() {
                o.push_str("//\n");
            } else {
                writeln!(o, "// {line}").unwrap();
            }
        }
        o.push_str("\n`default_nettype none\n\n");
        write!(o, "module {}", self.name).unwrap();
        if !self.params.is_empty() {
            o.push_str(" #(\n");
            for (k, p) in self.params.iter().enumerate() {
                let comma = if k + 1 < self.params.len() { "," } else { "" };
                writeln!(o, "  parameter {} = {}{comma}  // {}", p.name, p.value, p.doc).unwrap();
            }
            o.push(')');
        }
        o.push_str(" (\n");
        let decls: Vec<String> = self
            .ports
            .iter()
            .map(|p| {
                let dir = match p.dir {
                    Dir::Input => "input  wire ",
                    Dir::Output if p.reg => "output reg  ",
                    Dir::Output => "output wire ",
                };
                let range = match &p.param_width {
                    Some(w) => format!("[{w}-1:0] "),
                    None => vrange(p.width, p.vector),
                };
                format!("{dir}{}{range}{}", sign(p.signed), p.name)
            })
            .collect();
        let pad = decls.iter().map(|d| d.len()).max().unwrap_or(0) + 1;
        for (k, (d, p)) in decls.iter().zip(&self.ports).enumerate() {
            for a in &p.attrs {
                writeln!(o, "  (* {a} *)").unwrap();
            }
            let comma = if k + 1 < self.ports.len() { "," } else { " " };
            let note = match (p.format.as_str(), p.doc.as_str()) {
                ("", doc) => doc.to_string(),
                (f, "") => f.to_string(),
                (f, doc) => format!("{f}; {doc}"),
            };
            writeln!(o, "  {d}{comma}{:w$}// {note}", "", w = pad - d.len()).unwrap();
        }
        o.push_str(");\n");
        render_items(&mut o, &self.body, 1);
        o.push_str("\nendmodule\n\n`default_nettype wire\n");
        o
    }
}

fn indent(o: &mut String, level: usize) {
    for _ in 0..level {
        o.push_str("  ");
    }
}

fn render_items(o: &mut String, items: &[Item], level: usize) {
    for item in items {
        if !matches!(item, Item::Blank) {
            indent(o, level);
        }
        match item {
            Item::Blank => o.push('\n'),
            Item::Comment(c) => writeln!(o, "// {c}").unwrap(),
            Item::Wire { name, width, signed, value } => {
                write!(o, "wire {}{}{name}", sign(*signed), range(*width)).unwrap();
                match value {
                    Some(v) => writeln!(o, " = {v};").unwrap(),
                    None => o.push_str(";\n"),
                }
            }
            Item::Bus { name, width } => writeln!(o, "wire {}{name};", vrange(*width, true)).unwrap(),
            Item::Reg { name, width, signed } => writeln!(o, "reg {}{}{name};", sign(*signed), range(*width)).unwrap(),
            Item::Localparam { name, width, value } => {
                let r = if *width == 0 { String::new() } else { range(*width) };
                writeln!(o, "localparam {r}{name} = {value};").unwrap()
            }
            Item::Sized { kind, name, width, value } => {
                let kind = match kind {
                    Kind::Wire => "wire",
                    Kind::Reg => "reg",
                    Kind::Localparam => "localparam",
                };
                write!(o, "{kind} [{width}-1:0] {name}").unwrap();
                match value {
                    Some(v) => writeln!(o, " = {v};").unwrap(),
                    None => o.push_str(";\n"),
                }
            }
            Item::Integer(name) => writeln!(o, "integer {name};").unwrap(),
            Item::Assign(l, r) => writeln!(o, "assign {l} = {r};").unwrap(),
            Item::Always(stmts) => {
                o.push_str("always @(posedge clk) begin\n");
                render_stmts(o, stmts, level + 1);
                indent(o, level);
                o.push_str("end\n");
            }
            Item::Instance { module, name, params, conns } => {
                write!(o, "{module} ").unwrap();
                if !params.is_empty() {
                    let ps: Vec<String> = params.iter().map(|(k, v)| format!(".{k}({v})")).collect();
                    write!(o, "#({}) ", ps.join(", ")).unwrap();
                }
                writeln!(o, "{name} (").unwrap();
                for (k, (port, sig)) in conns.iter().enumerate() {
                    indent(o, level + 1);
                    let comma = if k + 1 < conns.len() { "," } else { "" };
                    writeln!(o, ".{port}({sig}){comma}").unwrap();
                }
                indent(o, level);
                o.push_str(");\n");
            }
            Item::ForGenerate { var, count, label, body } => {
                writeln!(o, "genvar {var};").unwrap();
                indent(o, level);
                o.push_str("generate\n");
                indent(o, level + 1);
                writeln!(o, "for ({var} = 0; {var} < {count}; {var} = {var} + 1) begin : {label}").unwrap();
                render_items(o, body, level + 2);
                indent(o, level + 1);
                o.push_str("end\n");
                indent(o, level);
                o.push_str("endgenerate\n");
            }
            Item::IfGenerate { cond, then, els } => {
                writeln!(o, "if ({cond}) begin : {}", then.0).unwrap();
                render_items(o, &then.1, level + 1);
                indent(o, level);
                writeln!(o, "end else begin : {}", els.0).unwrap();
                render_items(o, &els.1, level + 1);
                indent(o, level);
                o.push_str("end\n");
            }
            Item::ReadMemH { file, mem } => writeln!(o, "initial $readmemh({file}, {mem});").unwrap(),
            Item::Memory { name, width, depth, no_rw_check } => {
                let attr = if *no_rw_check { "(* no_rw_check *) " } else { "" };
                writeln!(o, "{attr}reg {}{name} [0:{}];", range(*width), depth - 1).unwrap()
            }
            Item::Initial(stmts) => {
                o.push_str("initial begin\n");
                render_stmts(o, stmts, level + 1);
                indent(o, level);
                o.push_str("end\n");
            }
            Item::Comb(stmts) => {
                o.push_str("always @(*) begin\n");
                render_stmts(o, stmts, level + 1);
                indent(o, level);
                o.push_str("end\n");
            }
            Item::Gather { name, lanes } => {
                o.push_str("always @(*) begin\n");
                indent(o, level + 1);
                // Most significant first, as a concatenation reads.
                let rows: Vec<String> =
                    lanes.chunks(GATHER_ROW).rev().map(|row| row.iter().rev().cloned().collect::<Vec<_>>().join(", ")).collect();
                if let [row] = rows.as_slice() {
                    writeln!(o, "{name} = {{{row}}};").unwrap();
                } else {
                    writeln!(o, "{name} = {{").unwrap();
                    for (k, row) in rows.iter().enumerate() {
                        indent(o, level + 2);
                        let comma = if k + 1 < rows.len() { "," } else { "" };
                        writeln!(o, "{{{row}}}{comma}").unwrap();
                    }
                    indent(o, level + 1);
                    o.push_str("};\n");
                }
                indent(o, level);
                o.push_str("end\n");
            }
            Item::RegInit { name, width, value } => writeln!(o, "reg {}{name} = {value};", range(*width)).unwrap(),
            Item::Formal(items) => render_ifdef(o, "FORMAL", &labelled(items), &[], level),
            Item::IfDef { name, then, els } => render_ifdef(o, name, then, els, level),
        }
    }
}

/// A formal block with every assert labelled `a_<section>_<n>` and every cover `c_<section>_<n>`:
/// the section is the first words of the comment above it, up to its colon ("Reset: ..." gives
/// `a_reset_0`), numbered in order within the module. A failing proof then names its property
/// (yosys-smtbmc prints the label), as SymbiYosys's examples do by hand.
fn labelled(items: &[Item]) -> Vec<Item> {
    let mut labeller = Labeller::default();
    labeller.items(items)
}

#[derive(Default)]
struct Labeller {
    section: String,
    counts: std::collections::HashMap<String, usize>,
}

impl Labeller {
    fn items(&mut self, items: &[Item]) -> Vec<Item> {
        items
            .iter()
            .map(|item| match item {
                Item::Comment(c) => {
                    self.heading(c);
                    item.clone()
                }
                Item::Always(stmts) => Item::Always(self.stmts(stmts)),
                Item::Comb(stmts) => Item::Comb(self.stmts(stmts)),
                Item::IfDef { name, then, els } => Item::IfDef { name: name.clone(), then: self.items(then), els: self.items(els) },
                other => other.clone(),
            })
            .collect()
    }

    fn stmts(&mut self, stmts: &[Stmt]) -> Vec<Stmt> {
        stmts
            .iter()
            .map(|s| match s {
                Stmt::Comment(c) => {
                    self.heading(c);
                    s.clone()
                }
                Stmt::Assert(_) => self.label("a", s),
                Stmt::Cover(_) => self.label("c", s),
                Stmt::If(c, then, els) => Stmt::If(c.clone(), self.stmts(then), self.stmts(els)),
                other => other.clone(),
            })
            .collect()
    }

    /// A comment that starts a sentence names the properties below it; a continuation line, a
    /// tool's tag or a lint pragma does not.
    fn heading(&mut self, comment: &str) {
        let sentence = comment.starts_with(|c: char| c.is_ascii_uppercase());
        let tag = comment.starts_with("scripts/prove") || comment.starts_with("verilator ");
        if sentence && !tag && !slug(comment).is_empty() {
            self.section = slug(comment);
        }
    }

    fn label(&mut self, kind: &str, s: &Stmt) -> Stmt {
        let section = if self.section.is_empty() { "property".to_string() } else { self.section.clone() };
        let n = self.counts.entry(format!("{kind}_{section}")).or_insert(0);
        let label = format!("{kind}_{section}_{n}");
        *n += 1;
        Stmt::Labelled(label, Box::new(s.clone()))
    }
}

/// The first three words of a comment before its colon (or full stop), articles apart, as an
/// identifier.
fn slug(comment: &str) -> String {
    let head = comment.split([':', '.', '(', ',', ';']).next().unwrap_or("");
    let words: Vec<String> = head
        .split(|c: char| !c.is_ascii_alphanumeric())
        .filter(|w| !w.is_empty())
        .skip_while(|w| ["a", "an", "the"].contains(&w.to_ascii_lowercase().as_str()))
        .take(3)
        .map(|w| w.to_ascii_lowercase())
        .collect();
    words.join("_")
}

/// `` `ifdef name `` `then` [`` `else `` `els`] `` `endif ``; preprocessor lines start at column 0,
/// like the file's `default_nettype.
fn render_ifdef(o: &mut String, name: &str, then: &[Item], els: &[Item], level: usize) {
    o.truncate(o.trim_end_matches(' ').len());
    writeln!(o, "`ifdef {name}").unwrap();
    render_items(o, then, level);
    if !els.is_empty() {
        o.push_str("`else\n");
        render_items(o, els, level);
    }
    o.push_str("`endif\n");
}

fn render_stmts(o: &mut String, stmts: &[Stmt], level: usize) {
    for s in stmts {
        indent(o, level);
        match s {
            Stmt::Set(l, r) => writeln!(o, "{l} <= {r};").unwrap(),
            Stmt::Comment(c) => writeln!(o, "// {c}").unwrap(),
            Stmt::Blocking(l, r) => writeln!(o, "{l} = {r};").unwrap(),
            Stmt::Call(c) => writeln!(o, "{c};").unwrap(),
            Stmt::Delay(n) => writeln!(o, "#{n};").unwrap(),
            Stmt::Assert(c) => writeln!(o, "assert({c});").unwrap(),
            Stmt::Assume(c) => writeln!(o, "assume({c});").unwrap(),
            Stmt::Cover(c) => writeln!(o, "cover({c});").unwrap(),
            Stmt::Labelled(label, stmt) => {
                let mut inner = String::new();
                render_stmts(&mut inner, std::slice::from_ref(stmt), level);
                write!(o, "{label}: {}", inner.trim_start()).unwrap();
            }
            Stmt::For { var, count, body } => {
                writeln!(o, "for ({var} = 0; {var} < {count}; {var} = {var} + 1) begin").unwrap();
                render_stmts(o, body, level + 1);
                indent(o, level);
                o.push_str("end\n");
            }
            Stmt::Case { sel, arms, default } => {
                writeln!(o, "case ({sel})").unwrap();
                for (label, body) in arms.iter().map(|(l, b)| (l.as_str(), b)).chain([("default", default)]) {
                    let mut inner = String::new();
                    render_stmts(&mut inner, body, 0);
                    indent(o, level + 1);
                    writeln!(o, "{label}: begin {}end", inner.replace('\n', " ")).unwrap();
                }
                indent(o, level);
                o.push_str("endcase\n");
            }
            Stmt::Forever(body) => {
                o.push_str("forever begin\n");
                render_stmts(o, body, level + 1);
                indent(o, level);
                o.push_str("end\n");
            }
            Stmt::If(cond, then, els) => {
                writeln!(o, "if ({cond}) begin").unwrap();
                render_stmts(o, then, level + 1);
                indent(o, level);
                match els.as_slice() {
                    [] => o.push_str("end\n"),
                    // `else if` chains read flatter than nested blocks.
                    [nested @ Stmt::If(..)] => {
                        o.push_str("end else ");
                        let mut inner = String::new();
                        render_stmts(&mut inner, std::slice::from_ref(nested), level);
                        o.push_str(inner.trim_start());
                    }
                    _ => {
                        o.push_str("end else begin\n");
                        render_stmts(o, els, level + 1);
                        indent(o, level);
                        o.push_str("end\n");
                    }
                }
            }
        }
    }
}
