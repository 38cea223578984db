//! The command line, run as a user runs it.

use std::path::Path;
use std::process::{Command, Output};

pub fn raycheck(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raycheck"))
        .args(args)
        .output()
        .expect("the raycheck binary runs")
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn scenes_lists_every_scene_with_its_triangle_count() {
    let out = raycheck(&["scenes"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    for (name, triangles) in [
        ("cornell", "32"),
        ("monkey", "3936"),
        ("dragon-11k", "11102"),
        ("dragon-48k", "47794"),
        ("dragon-203k", "202520"),
        ("dragon-871k", "871414"),
    ] {
        let line = text
            .lines()
            .find(|l| l.split_whitespace().next() == Some(name))
            .unwrap_or_else(|| panic!("{name} missing from:\n{text}"));
        assert_eq!(line.split_whitespace().nth(1), Some(triangles), "{line}");
    }
}

#[test]
fn compare_writes_the_promised_json() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("cornell.json");
    let out = raycheck(&[
        "compare",
        "cornell",
        "--res",
        "64",
        "--json",
        json.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stdout(&out).contains("embree-robust"), "{}", stdout(&out));
    let value: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    for key in [
        "scene",
        "triangles",
        "backends",
        "verdicts",
        "against_first",
        "samples",
    ] {
        assert!(value.get(key).is_some(), "missing {key} in {value}");
    }
    assert_eq!(value["scene"], "cornell");
    assert_eq!(value["triangles"], 32);
    let verdicts = &value["verdicts"];
    assert!(verdicts["rays"].as_u64().unwrap() > 64 * 64, "{verdicts}");
    let ours = &verdicts["backends"][0];
    assert_eq!(ours["name"], "ours", "{verdicts}");
    assert_eq!(ours["wrong"], 0, "{verdicts}");
    let against = &value["against_first"];
    assert_eq!(against.as_array().unwrap().len(), 2, "{against}");
    for key in [
        "hit_mismatch",
        "prim_mismatch",
        "max_rel_t_error",
        "hit_agreement",
    ] {
        assert!(against[0].get(key).is_some(), "missing {key} in {against}");
    }
}

#[test]
fn render_writes_a_png_of_the_asked_size() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("cornell.png");
    let out = raycheck(&[
        "render",
        "cornell",
        "--res",
        "40x30",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let img = image::open(&png).unwrap();
    assert_eq!((img.width(), img.height()), (40, 30));
}

#[test]
fn explain_lists_only_the_passes_the_scene_needs() {
    let out = raycheck(&["render", "monkey", "--explain"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(text.contains("hard shadows"), "{text}");
    assert!(!text.contains("reflection"), "{text}");
}

#[test]
fn debug_views_write_images_and_state_their_legend() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("heat.png");
    let path = png.to_str().unwrap();
    let out = raycheck(&[
        "render",
        "monkey",
        "--res",
        "32",
        "--backend",
        "ours-sah",
        "--debug",
        "heat",
        "-o",
        path,
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = stdout(&out);
    let max: u32 = text
        .split(" to ")
        .nth(1)
        .and_then(|rest| rest.split_whitespace().next()?.parse().ok())
        .unwrap_or_else(|| panic!("no max count in: {text}"));
    assert!(max > 1, "{text}");
    assert_eq!(image::open(&png).unwrap().width(), 32);
    for (args, expected) in [
        (&["--debug", "heatmap"][..], "unknown debug view 'heatmap'"),
        (
            &["--debug", "heat", "--backend", "embree"],
            "--backend ours",
        ),
        (&["--debug", "rays=40,2"], "outside the 32×32 image"),
        (&["--debug", "bvh-level=64"], "beyond the tree"),
    ] {
        let mut all = vec!["render", "cornell", "--res", "32", "-o", path];
        all.extend_from_slice(args);
        let out = raycheck(&all);
        assert!(!out.status.success(), "{args:?}");
        let err = stderr(&out);
        assert!(err.contains(expected), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}

#[test]
fn a_bad_mesh_fails_with_the_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("bad.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n").unwrap();
    let out = raycheck(&["render", obj.to_str().unwrap(), "-o", "unused.png"]);
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(err.contains("bad.obj:4"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(!Path::new("unused.png").exists());
}

#[test]
fn report_forms_are_exclusive() {
    let out = raycheck(&["report", "--quick", "--full", "--out", "unused"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("cannot be used with"),
        "{}",
        stderr(&out)
    );
    assert!(!Path::new("unused").exists());
}

#[test]
fn a_crate_that_panics_on_a_mesh_is_a_note_not_a_backtrace() {
    let out = raycheck(&[
        "stability",
        "--quick",
        "--case",
        "nan_and_inf",
        "--backends",
        "ours,obvhs,bvh",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    for crate_name in ["obvhs", "bvh"] {
        assert!(
            err.contains(&format!(
                "note: {crate_name} skipped on one mesh: {crate_name} panicked while building"
            )),
            "{err}"
        );
    }
    assert!(!err.contains("panicked at"), "{err}");
    assert!(!err.contains("stack backtrace"), "{err}");
}

/// `--kernel` and `--embree-isa` reach the run: perf's stamp names the
/// kernel ours ran and the ISA Embree reported selecting under the
/// ceiling asked, and a kernel this CPU lacks, or an unknown one, is a
/// clear error before anything runs. `--scenes` times only the scenes
/// named, and an unknown one is an error naming it.
#[test]
fn the_kernel_and_embrees_isa_are_chosen_on_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("perf.json");
    let out = raycheck(&[
        "perf",
        "--quick",
        "--scenes",
        "monkey,cornell",
        "--threads",
        "1",
        "--kernel",
        "scalar",
        "--embree-isa",
        "avx2",
        "--json",
        json.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(report["kernel"], "scalar", "{report}");
    let scenes: Vec<&str> = report["rows"]
        .as_array()
        .unwrap()
        .iter()
        .map(|row| row["scene"].as_str().unwrap())
        .collect();
    assert_eq!(scenes.first(), Some(&"monkey"), "{scenes:?}");
    assert!(scenes.contains(&"cornell"), "{scenes:?}");
    assert!(
        scenes.iter().all(|s| ["monkey", "cornell"].contains(s)),
        "{scenes:?}"
    );
    let isa = report["embree_isa"].as_str().unwrap();
    assert!(
        isa.starts_with("avx2 (selected, ") && isa.ends_with("; asked avx2)"),
        "{isa}"
    );
    assert!(
        stdout(&out).contains("ours: kernel scalar · Embree: isa avx2"),
        "{}",
        stdout(&out)
    );
    let out = raycheck(&["perf", "--quick", "--scenes", "cornell,nowhere"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("`nowhere`") && stderr(&out).contains("cornell, cornell-area"),
        "{}",
        stderr(&out)
    );
    let out = raycheck(&["compare", "cornell", "--res", "8", "--kernel", "avx3"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("avx3"), "{}", stderr(&out));
    if !std::arch::is_x86_feature_detected!("avx512f") {
        let out = raycheck(&["compare", "cornell", "--res", "8", "--kernel", "avx512"]);
        assert_eq!(out.status.code(), Some(2));
        assert!(
            stderr(&out).contains("this CPU does not have"),
            "{}",
            stderr(&out)
        );
    }
}
