//! The committed `rtl/` folder is exactly what `hdl-gen generate --p 8 --out rtl` writes, so it
//! can never go stale behind a generator change.

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
