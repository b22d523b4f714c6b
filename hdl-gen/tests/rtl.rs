//! The committed `rtl/` folder is exactly what `hdl-gen generate --p 8 --out rtl` writes, so it
//! can never go stale behind a generator change.

use golden::frontend::DiMode;
use hdl_gen::{generate, Options};

#[test]
fn committed_rtl_matches_the_generator() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../rtl");
    let files = generate(&Options::default());
    let mut on_disk: Vec<String> =
        std::fs::read_dir(&dir).expect("rtl/ exists").map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    on_disk.sort();
    let mut wanted: Vec<String> = files.iter().map(|f| f.name.clone()).collect();
    wanted.sort();
    let regen = "regenerate with: cargo run --release -p hdl-gen -- generate --p 8 --out rtl";
    assert_eq!(on_disk, wanted, "rtl/ holds other files than the generator writes; {regen}");
    for f in &files {
        let committed = std::fs::read_to_string(dir.join(&f.name)).unwrap();
        assert!(committed == f.contents, "rtl/{} is stale; {regen}", f.name);
    }
}

/// Issue 27's review criterion, kept: the front-end's dividers are instances of one module and
/// its edges one `generate` loop, at every form (a copy of a divider's step or of an edge fails it).
#[test]
fn dividers_and_edges_are_instances_not_copies() {
    for (di, pipeline, bits) in [(DiMode::Triangle, 0, 4), (DiMode::Triangle, 1, 1), (DiMode::Scanline, 0, 2), (DiMode::Scanline, 2, 4)] {
        let opts = Options {
            prefix: "x_".into(),
            fe_di: di,
            fe_div_bits: Some(bits),
            pipeline: golden::pipeline::Pipeline::at(pipeline),
            ..Default::default()
        };
        let files = generate(&opts);
        let text = |name: &str| files.iter().find(|f| f.name == name).unwrap_or_else(|| panic!("{name} generated")).contents.clone();
        let (top, edge, div) = (text("x_tri_frontend.v"), text("x_tri_fe_edge.v"), text("x_tri_fe_div.v"));
        let what = format!("{di:?}, level {pipeline}, {bits} bits");
        let scan = di == DiMode::Scanline;
        assert_eq!(top.matches("x_tri_fe_div #(").count(), if scan { 3 } else { 2 }, "{what}: u_ddi, u_drn (u_sdv)");
        assert_eq!(top.matches("x_tri_fe_edge u_edge (").count(), 1, "{what}");
        assert!(top.contains("for (k = 0; k < 3; k = k + 1) begin : g_edge\n"), "{what}");
        assert_eq!(edge.matches("x_tri_fe_div #(").count(), 2, "{what}: an edge's first bound and step");
        assert_eq!(div.matches("for (j = 0; j < BITS; j = j + 1) begin").count(), 1, "{what}: the steps a loop");
        for t in [&edge, &div, &top] {
            assert!(!t.contains("_p1 ") && !t.contains("_on0 "), "{what}: an unrolled divider step");
            assert_eq!(t.matches("\nmodule ").count(), 1, "{what}: one module per file");
        }
    }
}
