//! The repository stands alone: no document links outside it (`../shared/` is not in a user's
//! clone), every relative link of a document leads to a file or folder of the repository, and
//! every "SPEC §N" citation, in the documents, the code and the generated Verilog, names a
//! section that docs/spec.md, the project's specification, has.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

fn repo() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
}

/// The section numbers of a specification: its `## N. Title` headings.
fn sections(spec: &str) -> BTreeSet<u32> {
    spec.lines().filter_map(|l| l.strip_prefix("## ")).filter_map(|h| h.split_once('.').and_then(|(n, _)| n.trim().parse().ok())).collect()
}

/// Every `§` followed by a number in a text (all of this project's cite the specification; a
/// `§` with a letter is a placeholder, as in "SPEC §N"), with its line.
fn citations(text: &str) -> Vec<(usize, u32)> {
    let mut out = Vec::new();
    for (k, line) in text.lines().enumerate() {
        for (i, _) in line.match_indices('§') {
            let digits: String = line[i + '§'.len_utf8()..].trim_start().chars().take_while(char::is_ascii_digit).collect();
            if let Ok(n) = digits.parse() {
                out.push((k + 1, n));
            }
        }
    }
    out
}

/// The relative link targets of a Markdown line (`[text](target)`; not URLs, not `#anchors`),
/// without their `#anchor`.
fn relative_links(line: &str) -> Vec<&str> {
    line.match_indices("](")
        .filter_map(|(i, _)| line[i + 2..].split_once(')').map(|(t, _)| t))
        .filter(|t| !t.is_empty() && !t.starts_with('#') && !t.contains("://") && !t.starts_with("mailto:"))
        .map(|t| t.split('#').next().unwrap())
        .collect()
}

/// Whether `path`, with its `..` resolved by name (no link followed), lies inside the repository.
fn inside(path: &Path) -> bool {
    let mut depth = 0i32;
    for c in path.strip_prefix(repo()).expect("a path under the repository").components() {
        match c {
            std::path::Component::ParentDir => depth -= 1,
            std::path::Component::Normal(_) => depth += 1,
            _ => {}
        }
        if depth < 0 {
            return false;
        }
    }
    true
}

/// The problems of one file: where `is_doc` (a Markdown file in folder `dir`), a link to
/// `../shared` or to a path that does not exist; and citations of sections `known` lacks.
fn problems(name: &str, text: &str, is_doc: bool, known: &BTreeSet<u32>) -> Vec<String> {
    let mut out = Vec::new();
    let dir = repo().join(name).parent().unwrap().to_path_buf();
    if is_doc {
        for (k, line) in text.lines().enumerate() {
            if line.contains("../shared") {
                out.push(format!("{name}:{}: points at ../shared, which a clone does not have: {line}", k + 1));
            }
            for target in relative_links(line) {
                // Inside the repository: a clone has nothing beside it (this machine may).
                if !inside(&dir.join(target)) || !dir.join(target).exists() {
                    out.push(format!("{name}:{}: links {target}, which the repository does not have", k + 1));
                }
            }
        }
    }
    for (line, n) in citations(text) {
        if !known.contains(&n) {
            out.push(format!("{name}:{line}: cites §{n}, which docs/spec.md does not have"));
        }
    }
    out
}

/// Every text file of the repository, except build output and the version control's own.
fn files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let path = e.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if path.is_dir() {
            if name != "target" && !name.starts_with('.') {
                files(&path, out);
            }
        } else {
            out.push(path);
        }
    }
}

fn spec_sections() -> BTreeSet<u32> {
    sections(&std::fs::read_to_string(repo().join("docs/spec.md")).expect("docs/spec.md, the specification"))
}

#[test]
fn the_specification_has_the_sections_everything_cites() {
    let known = spec_sections();
    assert_eq!(known, (1..=7).collect(), "docs/spec.md keeps its section numbers 1..7: code and documents cite them");
    let mut all = Vec::new();
    files(repo(), &mut all);
    let (mut problems_found, mut cited, mut docs) = (Vec::new(), 0, 0);
    for path in &all {
        let Ok(text) = std::fs::read_to_string(path) else { continue }; // not text
        let rel = path.strip_prefix(repo()).unwrap().to_string_lossy().into_owned();
        let is_doc = rel.ends_with(".md");
        docs += usize::from(is_doc);
        cited += citations(&text).len();
        problems_found.extend(problems(&rel, &text, is_doc, &known));
    }
    assert!(docs >= 15 && cited >= 100, "the walk sees the documents ({docs}) and their citations ({cited})");
    assert!(problems_found.is_empty(), "{}", problems_found.join("\n"));
}

/// The negative control: a planted document that links ../shared and cites a section the
/// specification lacks is caught, each at its line; the real specification's sections pass.
#[test]
fn a_planted_citation_or_shared_link_is_caught() {
    let known = spec_sections();
    // Built at run time, so that this file itself cites no missing section.
    let missing = 99;
    let planted = format!(
        "# A page\n\nSee [SPEC](../shared/SPEC.md).\nAs SPEC §3 and § {missing} say.\n\
         [ok](docs/spec.md#2-parameters), [web](https://example.com/x), [gone](docs/gone.md).\n"
    );
    let found = problems("planted.md", &planted, true, &known);
    assert_eq!(found.len(), 4, "{found:#?}");
    assert!(found[0].starts_with("planted.md:3: points at ../shared"), "{}", found[0]);
    assert!(found[1].starts_with("planted.md:3: links ../shared/SPEC.md"), "{}", found[1]);
    assert!(found[2].starts_with("planted.md:5: links docs/gone.md"), "{}", found[2]);
    assert!(found[3].starts_with(&format!("planted.md:4: cites §{missing}")), "{}", found[3]);
    // The same text in code is not a document: only its citations count.
    assert_eq!(problems("planted.rs", &planted, false, &known).len(), 1);
    assert!(problems("ok.md", "SPEC §1, §2 and §7.\n", true, &known).is_empty());
    assert_eq!(sections("## 1. One\ntext\n## 12. Twelve\n### 3. not a section\n"), BTreeSet::from([1, 12]));
}
