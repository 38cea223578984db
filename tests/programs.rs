//! Programs as backends inside the commands: the C++ template through
//! `compare`, a wrong answer planted in a program's hits file counted on
//! exactly that ray, a crashing and a hanging program each reported by
//! name while the rest of the run goes on, and no program left running
//! when raycheck is killed.

use crate::cli::{raycheck, stderr, stdout};
use std::path::Path;

/// The C++ template's command, compiled into the cache if it is not there.
fn cpp_template() -> String {
    let out = raycheck(&["adapter", "cpp-template"]);
    assert!(out.status.success(), "{}", stderr(&out));
    stdout(&out).trim_end().to_string()
}

/// A wrapper that runs the program given before the three files, then
/// makes the first hit of a closest-hit batch (set codes other than the
/// any-hit 2 and 6) a miss: one wrong answer, on a ray the checked backend
/// hits.
const PLANT: &str = r#"
import struct, subprocess, sys
*command, mesh, rays, hits = sys.argv[1:]
subprocess.run(command + [mesh, rays, hits], check=True)
data = bytearray(open(hits, "rb").read())
set_code, count = struct.unpack_from("<IQ", data, 12)
if set_code not in (2, 6):
    for i in range(count):
        at = 32 + 16 * i
        if struct.unpack_from("<I", data, at + 12)[0] != 0xFFFFFFFF:
            struct.pack_into("<I", data, at + 12, 0xFFFFFFFF)
            break
open(hits, "wb").write(bytes(data))
"#;

/// A tracers file in `dir` with the given `[tracer.NAME]` bodies.
fn tracers_file(dir: &Path, tracers: &[(&str, String)]) -> String {
    let text: String = tracers
        .iter()
        .map(|(name, body)| format!("[tracer.{name}]\n{body}\n"))
        .collect();
    let path = dir.join("tracers.toml");
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_string()
}

/// `words` as a TOML array of strings.
fn toml_command(words: &[&str]) -> String {
    let quoted: Vec<String> = words.iter().map(|w| format!("{w:?}")).collect();
    format!("command = [{}]", quoted.join(", "))
}

/// The row of `backend` in a compare table: its wrong count.
fn wrong(table: &str, backend: &str) -> u64 {
    let row = table
        .lines()
        .find(|l| l.split_whitespace().next() == Some(backend))
        .unwrap_or_else(|| panic!("no row for {backend} in:\n{table}"));
    row.split_whitespace().nth(1).unwrap().parse().unwrap()
}

#[test]
fn a_program_is_checked_in_compare_and_a_planted_wrong_answer_is_counted() {
    let dir = tempfile::tempdir().unwrap();
    let template = cpp_template();
    let script = dir.path().join("plant.py");
    std::fs::write(&script, PLANT).unwrap();
    let mut planted = vec!["python3", script.to_str().unwrap()];
    planted.extend(template.split(' '));
    let tracers = tracers_file(dir.path(), &[("planted", toml_command(&planted))]);
    let out = raycheck(&[
        "compare",
        "cornell",
        "--res",
        "24",
        "--backends",
        "ours,embree-robust,cpp-template,planted",
        "--tracers",
        &tracers,
    ]);
    let text = stdout(&out);
    assert_eq!(out.status.code(), Some(0), "{text}\n{}", stderr(&out));
    assert_eq!(wrong(&text, "cpp-template"), 0, "{text}");
    assert_eq!(wrong(&text, "planted"), 1, "{text}");
    assert_eq!(wrong(&text, "ours"), 0, "{text}");
    // The programs' table: both ran, over one mesh.
    for name in ["cpp-template", "planted"] {
        let row = text
            .lines()
            .rev()
            .find(|l| l.starts_with(name))
            .unwrap_or_else(|| panic!("no program row for {name}:\n{text}"));
        assert!(row.ends_with("ran"), "{row}");
    }
}

#[test]
fn a_crashing_and_a_hanging_program_are_named_and_the_rest_runs() {
    let dir = tempfile::tempdir().unwrap();
    let tracers = tracers_file(
        dir.path(),
        &[
            (
                "crashes",
                toml_command(&["sh", "-c", "echo out of memory >&2; exit 3", "crashes"]),
            ),
            (
                "hangs",
                toml_command(&["sh", "-c", "sleep 60", "hangs"]) + "\ntimeout_seconds = 1",
            ),
        ],
    );
    let out = raycheck(&[
        "compare",
        "cornell",
        "--res",
        "16",
        "--backends",
        "ours,embree-robust,crashes,hangs",
        "--tracers",
        &tracers,
    ]);
    let (text, errors) = (stdout(&out), stderr(&out));
    assert_eq!(out.status.code(), Some(2), "{text}\n{errors}");
    // The rest of the run is intact: ours and Embree judged.
    assert_eq!(wrong(&text, "ours"), 0, "{text}");
    assert_eq!(wrong(&text, "embree-robust"), 0, "{text}");
    assert!(
        errors.contains("error: crashes was left out")
            && errors.contains("exit status: 3")
            && errors.contains("out of memory"),
        "{errors}"
    );
    assert!(
        errors.contains("error: hangs was left out")
            && errors.contains("ran past its time limit of 1 s"),
        "{errors}"
    );
}

#[test]
fn a_program_cannot_be_the_checked_backend() {
    let out = raycheck(&[
        "compare",
        "cornell",
        "--res",
        "8",
        "--backends",
        "cpp-template,ours",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("cpp-template is a program, so it cannot be the checked backend"),
        "{}",
        stderr(&out)
    );
}

/// The verdicts of `backend` (and of every backend beside it) in the JSON
/// of `stability --json` for its one case, and in the JSON of `judge` on a
/// bundle, the hits' column renamed to `backend`.
fn case_verdicts(json: &Path, judged_hits_as: Option<&str>) -> serde_json::Value {
    let value: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    let mut verdicts = match judged_hits_as {
        None => {
            let cases = value.as_array().unwrap();
            assert_eq!(cases.len(), 1, "{value}");
            cases[0]["verdicts"].clone()
        }
        Some(name) => {
            let mut verdicts = value["verdicts"].clone();
            let backends = verdicts["backends"].as_array_mut().unwrap();
            let mut hits = backends.remove(0);
            hits["name"] = name.into();
            backends.push(hits);
            verdicts
        }
    };
    let backends = verdicts["backends"].as_array_mut().unwrap();
    backends.sort_by_key(|b| b["name"].as_str().unwrap().to_string());
    verdicts
}

/// A program in `stability` is asked the rays the case asks, batch by
/// batch: its verdicts there are those of the case exported as a bundle,
/// traced by the same program and judged, beside the same backends. The
/// C++ template on a case of one mesh and on one of 160 placements, and
/// trimesh (a Python adapter) on the first.
#[test]
fn a_program_judges_the_same_in_stability_as_through_a_bundle() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let ran = |args: &[&str]| {
        let out = raycheck(args);
        assert!(
            matches!(out.status.code(), Some(0 | 1)),
            "{args:?}: {}{}",
            stdout(&out),
            stderr(&out)
        );
    };
    for (program, case) in [
        ("cpp-template", "closed_mesh_leaks"),
        ("cpp-template", "scale_and_offset"),
        ("trimesh", "closed_mesh_leaks"),
    ] {
        let stability = path(&format!("{program}-{case}-stability.json"));
        let backends = format!("ours,embree-robust,{program}");
        ran(&[
            "stability",
            "--quick",
            "--case",
            case,
            "--backends",
            &backends,
            "--json",
            &stability,
        ]);
        let bundle = path(&format!("{case}-bundle"));
        if !Path::new(&bundle).exists() {
            ran(&["rays", "--set", case, "--out", &bundle]);
        }
        let hits = path(&format!("{program}-{case}-hits"));
        ran(&["trace", &bundle, "--backend", program, "--out", &hits]);
        let judged = path(&format!("{program}-{case}-judged.json"));
        ran(&[
            "judge",
            &bundle,
            &hits,
            "--backends",
            "ours,embree-robust",
            "--json",
            &judged,
        ]);
        let in_stability = case_verdicts(Path::new(&stability), None);
        let through_files = case_verdicts(Path::new(&judged), Some(program));
        assert_eq!(in_stability, through_files, "{program} on {case}");
        assert!(
            in_stability["judged"].as_u64().unwrap() > 0,
            "{program} on {case}: nothing judged: {in_stability}"
        );
    }
}

/// A case with NaN or infinite vertices (`nan_and_inf`) cannot be handed
/// to a program (no mesh file reader takes one): the program is counted as
/// not built over those meshes, as a crate that refuses a mesh is, and is
/// not left out of the run.
#[test]
fn a_mesh_no_file_can_carry_is_a_build_failure_not_a_failed_program() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("nan.json");
    let out = raycheck(&[
        "stability",
        "--quick",
        "--case",
        "nan_and_inf",
        "--backends",
        "ours,embree-robust,cpp-template",
        "--json",
        json.to_str().unwrap(),
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}{}",
        stdout(&out),
        stderr(&out)
    );
    assert!(!stderr(&out).contains("was left out"), "{}", stderr(&out));
    let cases: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let backends = cases[0]["verdicts"]["backends"].as_array().unwrap();
    let program = backends
        .iter()
        .find(|b| b["name"] == "cpp-template")
        .unwrap();
    assert!(program["build_failures"].as_u64().unwrap() > 0, "{program}");
    assert_eq!(program["wrong"], 0, "{program}");
}

/// Whether process `pid` is gone (or a zombie no one has reaped yet).
#[cfg(target_os = "linux")]
fn gone(pid: &str) -> bool {
    std::fs::read_to_string(format!("/proc/{pid}/stat")).map_or(true, |stat| {
        stat.rsplit(')')
            .next()
            .unwrap()
            .trim_start()
            .starts_with('Z')
    })
}

#[test]
#[cfg(target_os = "linux")]
fn a_program_does_not_outlive_a_killed_raycheck() {
    use std::time::{Duration, Instant};
    let dir = tempfile::tempdir().unwrap();
    let pid_file = dir.path().join("pid");
    let script = format!("echo $$ > {}; exec sleep 120", pid_file.display());
    let tracers = tracers_file(
        dir.path(),
        &[("lingers", toml_command(&["sh", "-c", &script, "lingers"]))],
    );
    let mut raycheck = std::process::Command::new(env!("CARGO_BIN_EXE_raycheck"))
        .args(["compare", "cornell", "--res", "8"])
        .args([
            "--backends",
            "ours,embree-robust,lingers",
            "--tracers",
            &tracers,
        ])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let started = Instant::now();
    let pid = loop {
        match std::fs::read_to_string(&pid_file) {
            Ok(text) if text.ends_with('\n') => break text.trim().to_string(),
            _ if started.elapsed() > Duration::from_secs(120) => {
                panic!("the program never started")
            }
            _ => std::thread::sleep(Duration::from_millis(20)),
        }
    };
    assert!(!gone(&pid), "the program {pid} should be running");
    raycheck.kill().unwrap();
    raycheck.wait().unwrap();
    let killed = Instant::now();
    while !gone(&pid) {
        assert!(
            killed.elapsed() < Duration::from_secs(10),
            "the program {pid} outlived raycheck"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}
