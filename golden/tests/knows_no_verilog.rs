//! golden knows no Verilog (docs/architecture.md, "Invariants"): it says what each block computes
//! and which registers it has, never how they are written, so it can judge RTL that hdl-gen did
//! not write. Its code and strings (comments aside) hold no Verilog keyword.

use std::path::{Path, PathBuf};

/// Words that only Verilog text would hold.
const VERILOG: &[&str] = &["endmodule", "module ", "always @", "posedge", "negedge", "assign ", "$readmemh(", "`ifdef", "initial begin"];

/// Each `file:line: word` of `text` where code or a string (not a `//` comment) holds a Verilog
/// word. A `//` inside a string cuts the rest of its line too: that can hide a word, never
/// invent one.
fn verilog_in(file: &str, text: &str) -> Vec<String> {
    let mut hits = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let code = line.split("//").next().unwrap_or("");
        hits.extend(VERILOG.iter().filter(|w| code.contains(*w)).map(|w| format!("{file}:{}: {w}", n + 1)));
    }
    hits
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).expect("golden/src reads") {
        let path = e.expect("a directory entry").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|x| x == "rs") {
            out.push(path);
        }
    }
}

#[test]
fn golden_holds_no_verilog() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    assert!(files.len() > 10, "golden/src has its files: {files:?}");
    let hits: Vec<String> =
        files.iter().flat_map(|f| verilog_in(&f.display().to_string(), &std::fs::read_to_string(f).expect("a source reads"))).collect();
    assert!(hits.is_empty(), "Verilog in golden (hdl-gen prints it from golden's plans):\n{}", hits.join("\n"));
}

/// The negative control: a planted module in code and in a string is found; the same words in
/// comments are not.
#[test]
fn the_check_finds_planted_verilog() {
    let planted = "fn f() -> &'static str {\n    \"always @(posedge clk) q <= d;\"\n}\nconst M: &str = \"endmodule\";\n";
    assert_eq!(verilog_in("x.rs", planted), ["x.rs:2: always @", "x.rs:2: posedge", "x.rs:4: endmodule"]);
    assert_eq!(verilog_in("x.rs", "/// the RTL's `module ` and `endmodule`\nlet x = 1; // assign it\n"), Vec::<String>::new());
}
