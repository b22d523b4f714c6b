//! The `hdl-gen` command line: deterministic output, and one clear error with exit status 2
//! and nothing written for every bad argument.

mod common;
use common::{hdl_gen, listing, scratch};

#[test]
fn same_command_same_bytes() {
    for args in [&["--p", "8"][..], &["--p", "64", "--align", "screen", "--prefix", "my_", "--frac", "10", "--xbits", "11"]] {
        let (a, b) = (scratch("det-a"), scratch("det-b"));
        for dir in [&a, &b] {
            let mut full = vec!["generate", "--out", dir.to_str().unwrap()];
            full.extend_from_slice(args);
            let out = hdl_gen(&full);
            assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        }
        let (la, lb) = (listing(&a), listing(&b));
        assert!(la.len() >= 4, "{la:?}");
        assert_eq!(la, lb, "two runs of {args:?} differ");
        for (name, _) in &la {
            assert!(!name.contains(".tmp"), "temporary file {name} left behind");
        }
    }
}

#[test]
fn prefix_applies_to_every_module() {
    let dir = scratch("prefix");
    let out = hdl_gen(&["generate", "--p", "4", "--prefix", "acme_", "--out", dir.to_str().unwrap()]);
    assert!(out.status.success());
    let seg = std::fs::read_to_string(dir.join("acme_segment_shader_p4.v")).unwrap();
    assert!(seg.contains("module acme_segment_shader_p4 ("));
    assert!(seg.contains("acme_bfpi_p4 u_bfpi"));
    assert!(dir.join("acme_bfpi_p4.v").exists());
}

#[test]
fn bad_arguments_exit_2_with_one_message_and_write_nothing() {
    let dir = scratch("bad");
    let d = dir.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["generate", "--p", "3", "--out", d], "power of two"),
        (&["generate", "--p", "0", "--out", d], "power of two"),
        (&["generate", "--p", "512", "--out", d], "power of two"),
        (&["generate", "--p", "eight", "--out", d], "--p"),
        (&["generate", "--frac", "3", "--out", d], "--frac"),
        (&["generate", "--frac", "21", "--out", d], "--frac"),
        (&["generate", "--xbits", "17", "--out", d], "--xbits"),
        (&["generate", "--xbits", "3", "--out", d], "--xbits"),
        (&["generate", "--p", "32", "--xbits", "4", "--out", d], "exceeds the screen width"),
        (&["generate", "--align", "diagonal", "--out", d], "--align"),
        (&["generate", "--prefix", "9lives", "--out", d], "--prefix"),
        (&["generate", "--p", "8"], "--out"),
        (&["frobnicate"], "frobnicate"),
    ];
    for (args, needle) in cases {
        let out = hdl_gen(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: message should name '{needle}': {err}");
        assert_eq!(err.matches("error").count(), 1, "{args:?}: one message: {err}");
        assert!(!dir.exists(), "{args:?} created {d}");
    }
}

#[test]
fn unwritable_output_folder_exits_2_and_leaves_nothing() {
    let base = scratch("unwritable");
    std::fs::create_dir_all(&base).unwrap();
    let file = base.join("a-file");
    std::fs::write(&file, "not a folder").unwrap();
    for out_dir in [file.clone(), file.join("sub")] {
        let out = hdl_gen(&["generate", "--out", out_dir.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains("error:") && err.contains(out_dir.to_str().unwrap()), "{err}");
    }
    assert_eq!(listing(&base).len(), 1, "only the original file remains");
    assert_eq!(std::fs::read(&file).unwrap(), b"not a folder");
}

/// `hdl-gen manifest` names the module of each role, prefix and all, as the scripts read it.
#[test]
fn manifest_names_the_module_of_a_role() {
    let dir = scratch("manifest-role");
    let d = dir.to_str().unwrap();
    assert!(hdl_gen(&["generate", "--out", d, "--p", "16", "--prefix", "my_"]).status.success());
    for (role, name) in [
        ("segment-shader", "my_segment_shader_p16"),
        ("frontend", "my_tri_frontend"),
        ("writer", "my_fb_writer_p16"),
        ("triangle-writer", "my_tri_fb_p16"),
        ("specular-unit", "my_specular_unit"),
    ] {
        let out = hdl_gen(&["manifest", "--rtl", d, "--role", role]);
        assert!(out.status.success(), "{role}: {}", String::from_utf8_lossy(&out.stderr));
        assert_eq!(String::from_utf8_lossy(&out.stdout), format!("{name}\n"), "{role}");
    }
}
