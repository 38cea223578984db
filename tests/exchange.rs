//! Rays out, hits in: the documented Python tracer, our own hits and
//! planted wrong answers, each through `raycheck rays`, `trace` and `judge`
//! as a user runs them.

use crate::cli::{raycheck, stderr, stdout};
use raycheck::check::Answer;
use raycheck::exchange::HitsFile;
use std::path::{Path, PathBuf};

/// Writes cornell's `set` rays at `res`² and its mesh into `dir`.
fn export(dir: &Path, set: &str, res: u32) -> (PathBuf, PathBuf) {
    let rays = dir.join(format!("{set}.rays"));
    let mesh = dir.join("cornell.ply");
    let res = res.to_string();
    let out = raycheck(&[
        "rays",
        "cornell",
        "--set",
        set,
        "--res",
        &res,
        "--out",
        rays.to_str().unwrap(),
        "--mesh-out",
        mesh.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    (rays, mesh)
}

/// Judges `hits`; returns the exit code and the JSON summary.
pub fn judge(mesh: &Path, rays: &Path, hits: &Path) -> (i32, serde_json::Value) {
    let json = hits.with_extension("json");
    let out = raycheck(&[
        "judge",
        mesh.to_str().unwrap(),
        rays.to_str().unwrap(),
        hits.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
    ]);
    assert!(
        !stderr(&out).contains("panicked"),
        "{}{}",
        stdout(&out),
        stderr(&out)
    );
    let summary = std::fs::read_to_string(&json)
        .unwrap_or_else(|_| panic!("no summary: {}{}", stdout(&out), stderr(&out)));
    (
        out.status.code().unwrap_or(-1),
        serde_json::from_str(&summary).unwrap(),
    )
}

/// The judged file's tally (the first backend's).
pub fn tally(summary: &serde_json::Value) -> (u64, u64) {
    let first = &summary["verdicts"]["backends"][0];
    (
        first["wrong"].as_u64().unwrap(),
        first["t_off"].as_u64().unwrap(),
    )
}

/// The first Python block after `heading` in docs/exchange.md, exactly as
/// printed there.
fn documented_python(heading: &str) -> String {
    let doc =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/exchange.md")).unwrap();
    let section = doc.find(heading).expect("the heading");
    let start =
        section + doc[section..].find("```python\n").expect("a python block") + "```python\n".len();
    let end = start + doc[start..].find("\n```").expect("its end");
    doc[start..end].to_string()
}

/// The Python tracer of docs/exchange.md.
fn documented_python_tracer() -> String {
    documented_python("## A tracer in Python")
}

#[test]
fn the_documented_python_tracer_is_judged_right() {
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("tracer.py");
    std::fs::write(&script, documented_python_tracer()).unwrap();
    for set in ["primary", "shadow"] {
        let (rays, mesh) = export(dir.path(), set, 24);
        let hits = dir.path().join(format!("{set}.hits"));
        let out = std::process::Command::new("python3")
            .args([&script, &mesh, &rays, &hits])
            .output()
            .expect("python3 runs");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let (code, summary) = judge(&mesh, &rays, &hits);
        assert_eq!(tally(&summary), (0, 0), "{set}: {summary}");
        assert_eq!(code, 0, "{set}: {summary}");
        assert!(summary["verdicts"]["rays"].as_u64().unwrap() > 24 * 24 / 2);
    }
}

/// The documented loop over a bundle, running the documented tracer on
/// every rays file, writes the hits `judge` reads: the built-in backends
/// beside them are judged as the case judges them.
#[test]
fn the_documented_bundle_loop_writes_what_judge_reads() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("tracer.py"), documented_python_tracer()).unwrap();
    std::fs::write(
        dir.path().join("trace_bundle.py"),
        documented_python("## Stability cases: bundles"),
    )
    .unwrap();
    let run = |program: &str, args: &[&str]| {
        let out = std::process::Command::new(program)
            .args(args)
            .current_dir(dir.path())
            .output()
            .expect("it runs");
        assert!(
            out.status.code().is_some_and(|c| c <= 1),
            "{program} {args:?}: {}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        out
    };
    let raycheck = env!("CARGO_BIN_EXE_raycheck");
    run(raycheck, &["rays", "--set", "tnear_tfar", "--out", "case"]);
    run("python3", &["trace_bundle.py", "case", "hits"]);
    run(
        raycheck,
        &["judge", "case", "hits", "--json", "verdicts.json"],
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("verdicts.json")).unwrap())
            .unwrap();
    let verdicts = &summary["verdicts"];
    assert_eq!(verdicts["backends"][0]["name"], "hits", "{summary}");
    assert_eq!(verdicts["backends"][1]["name"], "ours", "{summary}");
    assert_eq!(verdicts["backends"][1]["wrong"], 0, "{summary}");
    assert!(verdicts["judged"].as_u64().unwrap() > 0, "{summary}");
    assert_eq!(
        summary["pairs"].as_array().unwrap().len(),
        std::fs::read_dir(dir.path().join("hits")).unwrap().count() / 2
    );
}

#[test]
fn our_hits_round_trip_and_planted_faults_are_each_caught() {
    let dir = tempfile::tempdir().unwrap();
    let (rays, mesh) = export(dir.path(), "primary", 48);
    let hits = dir.path().join("ours.hits");
    let out = raycheck(&[
        "trace",
        mesh.to_str().unwrap(),
        rays.to_str().unwrap(),
        "--backend",
        "ours",
        "--out",
        hits.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let (code, summary) = judge(&mesh, &rays, &hits);
    assert_eq!((code, tally(&summary)), (0, (0, 0)), "{summary}");

    // Plant faults on hits well inside their triangles, where no one-ulp
    // change can make them right: dropped hits, a hit moved to another
    // triangle, hits moved along the ray.
    let mut file = HitsFile::read(&hits).unwrap();
    let interior: Vec<usize> = (0..file.answers.len())
        .filter(|&i| match file.answers[i] {
            Answer::Closest(Some(h)) => h.u > 0.1 && h.v > 0.1 && h.u + h.v < 0.9,
            _ => false,
        })
        .step_by(97)
        .take(6)
        .collect();
    assert_eq!(interior.len(), 6);
    let triangles = 32;
    for (k, &i) in interior.iter().enumerate() {
        let Answer::Closest(Some(hit)) = file.answers[i] else {
            unreachable!()
        };
        file.answers[i] = match k {
            0 | 1 => Answer::Closest(None),
            2 => Answer::Closest(Some(raycheck::geometry::Hit {
                prim: (hit.prim + triangles / 2) % triangles,
                ..hit
            })),
            _ => Answer::Closest(Some(raycheck::geometry::Hit {
                t: hit.t * 1.01,
                ..hit
            })),
        };
    }
    let planted = dir.path().join("planted.hits");
    file.write(&planted).unwrap();
    let (code, summary) = judge(&mesh, &rays, &planted);
    assert_eq!(code, 1, "{summary}");
    assert_eq!(tally(&summary), (3, 3), "{summary}");
    // Each planted ray is among the replayable samples, judged as planted.
    let samples = summary["samples"].as_array().unwrap();
    let file = raycheck::exchange::RaysFile::read(&rays).unwrap();
    for (k, &i) in interior.iter().enumerate() {
        let bits = format!("{:#010x}", file.rays[i].origin.x.to_bits());
        let dir_x = format!("{:#010x}", file.rays[i].dir.x.to_bits());
        let sample = samples
            .iter()
            .find(|s| s["ray"]["bits"][0] == bits.as_str() && s["ray"]["bits"][3] == dir_x.as_str())
            .unwrap_or_else(|| panic!("planted ray {i} not sampled: {summary}"));
        let expected = if k < 3 { "wrong" } else { "distance_off" };
        assert_eq!(sample["answers"][0]["judgement"], expected, "{sample}");
    }
}

/// A tracer that gives no `u`, `v` may leave anything in their place: with
/// flag bit 0 clear, NaN and huge values there are neither read nor
/// compared.
#[test]
fn u_and_v_without_their_flag_are_not_compared() {
    let dir = tempfile::tempdir().unwrap();
    let (rays, mesh) = export(dir.path(), "primary", 32);
    let hits = dir.path().join("ours.hits");
    let out = raycheck(&[
        "trace",
        mesh.to_str().unwrap(),
        rays.to_str().unwrap(),
        "--out",
        hits.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let mut bytes = std::fs::read(&hits).unwrap();
    assert_eq!(bytes[24], 1, "ours gives u, v");
    bytes[24] = 0;
    let garbage = [f32::NAN, 1e30, -7.0, f32::INFINITY];
    for (i, record) in bytes[32..].chunks_mut(16).enumerate() {
        record[4..8].copy_from_slice(&garbage[i % 4].to_le_bytes());
        record[8..12].copy_from_slice(&garbage[(i + 1) % 4].to_le_bytes());
    }
    let flagless = dir.path().join("flagless.hits");
    std::fs::write(&flagless, bytes).unwrap();
    let (code, summary) = judge(&mesh, &rays, &flagless);
    assert_eq!((code, tally(&summary)), (0, (0, 0)), "{summary}");
    assert_eq!(summary["verdicts"]["backends"][0]["nan_outputs"], 0);
    for other in summary["against_first"].as_array().unwrap() {
        assert!(other["max_uv_error"].is_null(), "{summary}");
    }
}

#[test]
fn bad_files_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let (rays, mesh) = export(dir.path(), "primary", 8);
    let hits = dir.path().join("ours.hits");
    raycheck(&[
        "trace",
        mesh.to_str().unwrap(),
        rays.to_str().unwrap(),
        "--out",
        hits.to_str().unwrap(),
    ]);
    let bytes = std::fs::read(&hits).unwrap();
    let (shadow_rays, _) = export(dir.path(), "shadow", 8);
    let mut cases: Vec<(&str, Vec<u8>, &Path, &str)> = vec![
        (
            "truncated",
            bytes[..bytes.len() - 3].to_vec(),
            &rays,
            "truncated",
        ),
        (
            "magic",
            [b"RCRAYS\0\0", &bytes[8..]].concat(),
            &rays,
            "not a raycheck hits file",
        ),
        (
            "other set",
            bytes.clone(),
            &shadow_rays,
            "the rays file holds",
        ),
    ];
    let mut nan = bytes.clone();
    nan[32..36].copy_from_slice(&f32::NAN.to_le_bytes());
    nan[44..48].copy_from_slice(&0u32.to_le_bytes());
    cases.push(("nan", nan, &rays, "answer 0: t is NaN"));
    // A short file whose header agrees with its body: it answers fewer
    // rays than the rays file holds.
    let count = u64::from_le_bytes(bytes[16..24].try_into().unwrap());
    let mut short = bytes[..bytes.len() - 2 * 16].to_vec();
    short[16..24].copy_from_slice(&(count - 2).to_le_bytes());
    let short_message = format!(
        "the hits answer {} rays of the primary set; the rays file holds {count} rays",
        count - 2
    );
    cases.push(("short", short, &rays, short_message.as_str()));
    let mut prim = bytes.clone();
    prim[44..48].copy_from_slice(&1000u32.to_le_bytes());
    cases.push((
        "prim",
        prim,
        &rays,
        "primID 1000 is beyond the mesh's 32 triangles",
    ));
    for (name, damaged, rays, expected) in cases {
        let path = dir.path().join(format!("{name}.hits"));
        std::fs::write(&path, damaged).unwrap();
        let out = raycheck(&[
            "judge",
            mesh.to_str().unwrap(),
            rays.to_str().unwrap(),
            path.to_str().unwrap(),
        ]);
        assert_eq!(out.status.code(), Some(2), "{name}");
        let err = stderr(&out);
        assert!(err.contains(expected), "{name}: {err}");
        assert!(!err.contains("panicked"), "{name}: {err}");
    }
}
