//! The tracers in `adapters/` as a user runs them: set up in the cache
//! (`raycheck adapter NAME`: a Python environment with pinned packages, or
//! the compiled C++ template), fed `raycheck rays` sets, judged by
//! `raycheck judge`; planted wrong answers, unknown sets, bad files and odd
//! rays; set-up without Python, a compiler or the network.

use crate::cli::{raycheck, stderr, stdout};
use crate::exchange::{judge, tally};
use raycheck::adapters::{Adapter, ProgramCommand, PythonEnv, SetupError, compile_cpp};
use raycheck::check::Answer;
use raycheck::exchange::files::{HEADER_BYTES, MISS};
use raycheck::exchange::{HitsFile, RaysFile};
use raycheck::geometry::{Hit, Ray};
use std::path::{Path, PathBuf};
use std::process::Output;

/// `adapter` set up in raycheck's cache (made once per machine).
fn prepared(adapter: Adapter) -> ProgramCommand {
    let cache = raycheck::scene::assets::cache_dir().unwrap();
    adapter
        .prepare(&cache)
        .unwrap_or_else(|e| panic!("{adapter:?}: {e}"))
}

/// Writes `scene`'s `set` rays at `res`² and its mesh into `dir`.
fn export(dir: &Path, scene: &str, set: &str, res: u32) -> (PathBuf, PathBuf) {
    let mesh = dir.join(format!("{scene}.ply"));
    let rays = dir.join(format!("{scene}-{set}.rays"));
    let out = raycheck(&[
        "rays",
        scene,
        "--set",
        set,
        "--res",
        &res.to_string(),
        "--out",
        rays.to_str().unwrap(),
        "--mesh-out",
        mesh.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    (mesh, rays)
}

/// Runs `command` on the three files.
fn trace(command: &ProgramCommand, mesh: &Path, rays: &Path, hits: &Path) -> Output {
    command
        .with_files(mesh, rays, hits)
        .output()
        .expect("the adapter starts")
}

/// Traces `scene`'s `sets` through `adapter` and asserts that `judge`
/// finds no answer wrong and no distance off.
fn judged_right(adapter: Adapter, scene: &str, sets: &[&str], res: u32) {
    let command = prepared(adapter);
    let dir = tempfile::tempdir().unwrap();
    for set in sets {
        let (mesh, rays) = export(dir.path(), scene, set, res);
        let hits = dir.path().join(format!("{set}.hits"));
        let out = trace(&command, &mesh, &rays, &hits);
        assert!(out.status.success(), "{command} {set}: {}", stderr(&out));
        let (code, summary) = judge(&mesh, &rays, &hits);
        let what = format!("{adapter:?} on {scene} {set}: {summary}");
        assert_eq!(tally(&summary), (0, 0), "{what}");
        assert_eq!(code, 0, "{what}");
        let count = RaysFile::read(&rays).unwrap().rays.len();
        assert!(count > 0, "{what}");
        assert_eq!(
            summary["verdicts"]["rays"].as_u64(),
            Some(count as u64),
            "{what}"
        );
    }
}

#[test]
fn mitsuba_scalar_is_judged_right_on_cornell() {
    judged_right(
        Adapter::MitsubaScalar,
        "cornell",
        &["primary", "shadow"],
        48,
    );
}

#[test]
fn mitsuba_llvm_is_judged_right_on_cornell_and_dragon_11k() {
    judged_right(Adapter::MitsubaLlvm, "cornell", &["primary", "shadow"], 48);
    judged_right(
        Adapter::MitsubaLlvm,
        "dragon-11k",
        &["primary", "shadow", "diffuse"],
        64,
    );
}

#[test]
fn trimesh_is_judged_right_on_cornell_and_dragon_11k() {
    judged_right(Adapter::Trimesh, "cornell", &["primary", "shadow"], 48);
    judged_right(
        Adapter::Trimesh,
        "dragon-11k",
        &["primary", "shadow", "diffuse"],
        64,
    );
}

#[test]
fn the_cpp_template_is_judged_right_on_cornell_and_dragon_11k() {
    judged_right(Adapter::CppTemplate, "cornell", &["primary", "shadow"], 48);
    judged_right(
        Adapter::CppTemplate,
        "dragon-11k",
        &["primary", "shadow", "diffuse"],
        64,
    );
}

#[test]
fn the_command_line_prints_the_prepared_command() {
    let out = raycheck(&["adapter", "cpp-template"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(
        stdout(&out).trim_end(),
        prepared(Adapter::CppTemplate).to_string()
    );
    let out = raycheck(&["adapter", "povray"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("mitsuba-llvm"), "{}", stderr(&out));
}

/// Whether a closest hit lies well inside its triangle and well before
/// `tfar`, where no one-ulp change of any input makes another answer right.
fn well_inside(hit: &Hit, tfar: f32) -> bool {
    hit.u > 0.1 && hit.v > 0.1 && hit.u + hit.v < 0.9 && hit.t < 0.9 * tfar
}

#[test]
fn wrong_answers_planted_in_an_adapters_output_are_counted() {
    let command = prepared(Adapter::CppTemplate);
    let dir = tempfile::tempdir().unwrap();
    let triangles = 32;

    // Closest hits: three hits well inside their triangles moved to another.
    let (mesh, rays) = export(dir.path(), "cornell", "primary", 48);
    let hits = dir.path().join("primary.hits");
    assert!(trace(&command, &mesh, &rays, &hits).status.success());
    let ray_file = RaysFile::read(&rays).unwrap();
    let mut file = HitsFile::read(&hits).unwrap();
    let planted: Vec<usize> = (0..file.answers.len())
        .filter(|&i| matches!(file.answers[i], Answer::Closest(Some(h)) if well_inside(&h, ray_file.rays[i].tfar)))
        .step_by(101)
        .take(3)
        .collect();
    assert_eq!(planted.len(), 3);
    for &i in &planted {
        if let Answer::Closest(Some(hit)) = &mut file.answers[i] {
            hit.prim = (hit.prim + triangles / 2) % triangles;
        }
    }
    file.write(&hits).unwrap();
    let (code, summary) = judge(&mesh, &rays, &hits);
    assert_eq!((code, tally(&summary)), (1, (3, 0)), "{summary}");

    // Occlusion: four occluded rays whose nearest blocker is well inside
    // its triangle and well before the light, flipped to "not occluded".
    // The nearest blocker is the template's closest hit of the same rays
    // asked as a closest-hit set.
    let (mesh, shadow) = export(dir.path(), "cornell", "shadow", 48);
    let mut bytes = std::fs::read(&shadow).unwrap();
    bytes[12..16].copy_from_slice(&3u32.to_le_bytes()); // the reflection set: closest hits
    let as_closest = dir.path().join("shadow-as-closest.rays");
    std::fs::write(&as_closest, &bytes).unwrap();
    let nearest = dir.path().join("nearest.hits");
    assert!(
        trace(&command, &mesh, &as_closest, &nearest)
            .status
            .success()
    );
    let nearest = HitsFile::read(&nearest).unwrap();
    let shadow_rays = RaysFile::read(&shadow).unwrap();
    let hits = dir.path().join("shadow.hits");
    assert!(trace(&command, &mesh, &shadow, &hits).status.success());
    let mut file = HitsFile::read(&hits).unwrap();
    let flipped: Vec<usize> = (0..file.answers.len())
        .filter(|&i| matches!(nearest.answers[i], Answer::Closest(Some(h)) if well_inside(&h, shadow_rays.rays[i].tfar)))
        .step_by(53)
        .take(4)
        .collect();
    assert_eq!(flipped.len(), 4);
    for &i in &flipped {
        assert_eq!(file.answers[i], Answer::Occluded(true), "ray {i}");
        file.answers[i] = Answer::Occluded(false);
    }
    file.write(&hits).unwrap();
    let (code, summary) = judge(&mesh, &shadow, &hits);
    assert_eq!((code, tally(&summary)), (1, (4, 0)), "{summary}");
}

/// The adapters that read files themselves: one per program.
const PROGRAMS: [Adapter; 3] = [Adapter::MitsubaLlvm, Adapter::Trimesh, Adapter::CppTemplate];

#[test]
fn unknown_sets_and_bad_files_are_refused_with_the_file_named() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, rays) = export(dir.path(), "cornell", "primary", 4);
    let bytes = std::fs::read(&rays).unwrap();
    let truncated_rays = dir.path().join("truncated.rays");
    std::fs::write(&truncated_rays, &bytes[..HEADER_BYTES + 40]).unwrap();
    let mut bytes = bytes;
    bytes[12..16].copy_from_slice(&9u32.to_le_bytes());
    let unknown = dir.path().join("unknown-set.rays");
    std::fs::write(&unknown, &bytes).unwrap();
    let ply = std::fs::read(&mesh).unwrap();
    let truncated_mesh = dir.path().join("truncated.ply");
    std::fs::write(&truncated_mesh, &ply[..ply.len() - 5]).unwrap();
    let hits = dir.path().join("out.hits");
    for adapter in PROGRAMS {
        let command = prepared(adapter);
        for (mesh, rays, file, what) in [
            (&mesh, &unknown, &unknown, "unknown ray set code 9"),
            (
                &mesh,
                &truncated_rays,
                &truncated_rays,
                "the header says 16 rays",
            ),
            (
                &truncated_mesh,
                &rays,
                &truncated_mesh,
                "bytes after the header",
            ),
        ] {
            let out = trace(&command, mesh, rays, &hits);
            let message = stderr(&out);
            assert_eq!(out.status.code(), Some(2), "{command}: {message}");
            assert!(
                message.contains(file.to_str().unwrap()) && message.contains(what),
                "{command}: expected {file:?} and {what:?} in: {message}"
            );
        }
    }
}

#[test]
fn odd_rays_are_answered_as_their_interval_says() {
    let dir = tempfile::tempdir().unwrap();
    let (mesh, _) = export(dir.path(), "cornell", "primary", 4);
    // From outside the box through its right wall (x = 0, t = 100) and on
    // to its left wall (x = 550 or so, t = 650).
    let origin = glam::Vec3::new(-100.0, 450.0, 300.0);
    let along = glam::Vec3::X;
    let rays = RaysFile {
        set: raycheck::check::RaySet::StabilityCase,
        rays: vec![
            Ray::new(origin, along),
            Ray::new(glam::Vec3::new(f32::NAN, 450.0, 300.0), along),
            Ray::segment(origin, along, 900.0, 100.0),
            Ray::segment(origin, along, 200.0, f32::INFINITY),
            Ray::segment(origin, along, 200.0, 300.0),
        ],
    };
    let file = dir.path().join("odd.rays");
    rays.write(&file).unwrap();
    let expected = {
        let hits = dir.path().join("template.hits");
        assert!(
            trace(&prepared(Adapter::CppTemplate), &mesh, &file, &hits)
                .status
                .success()
        );
        HitsFile::read(&hits).unwrap().answers
    };
    let prim = |answer: &Answer| match answer {
        Answer::Closest(Some(hit)) => hit.prim,
        _ => MISS,
    };
    let right_wall = [8, 9];
    let left_wall = [10, 11];
    let expected_prims: Vec<u32> = expected.iter().map(prim).collect();
    assert!(right_wall.contains(&expected_prims[0]), "{expected:?}");
    assert!(left_wall.contains(&expected_prims[3]), "{expected:?}");
    assert_eq!(
        [expected_prims[1], expected_prims[2], expected_prims[4]],
        [MISS; 3]
    );
    for adapter in [
        Adapter::MitsubaScalar,
        Adapter::MitsubaLlvm,
        Adapter::Trimesh,
    ] {
        let hits = dir.path().join(format!("{adapter:?}.hits"));
        let out = trace(&prepared(adapter), &mesh, &file, &hits);
        assert!(out.status.success(), "{adapter:?}: {}", stderr(&out));
        let answers = HitsFile::read(&hits).unwrap().answers;
        assert_eq!(
            answers.iter().map(prim).collect::<Vec<_>>(),
            expected_prims,
            "{adapter:?}"
        );
        let (code, summary) = judge(&mesh, &file, &hits);
        assert_eq!((code, tally(&summary)), (0, (0, 0)), "{summary}");
    }

    // Hits behind the origin cannot be asked of either library.
    let behind = RaysFile {
        set: raycheck::check::RaySet::StabilityCase,
        rays: vec![Ray::segment(origin, along, -1.0, f32::INFINITY)],
    };
    behind.write(&file).unwrap();
    for adapter in [Adapter::MitsubaLlvm, Adapter::Trimesh] {
        let out = trace(&prepared(adapter), &mesh, &file, &dir.path().join("x.hits"));
        assert_eq!(out.status.code(), Some(2), "{adapter:?}");
        assert!(
            stderr(&out).contains("tnear < 0"),
            "{adapter:?}: {}",
            stderr(&out)
        );
    }
}

#[test]
fn a_missing_python_or_compiler_is_named() {
    let cache = tempfile::tempdir().unwrap();
    let error = PythonEnv::ensure(
        cache.path(),
        "/nonexistent/python3".as_ref(),
        "x",
        "rtree==1.4.1",
    )
    .unwrap_err();
    assert!(
        matches!(&error, SetupError::Missing { program, .. } if program == "/nonexistent/python3"),
        "{error}"
    );
    assert!(error.to_string().contains("install Python 3"), "{error}");
    let error = compile_cpp(
        cache.path(),
        "/nonexistent/g++".as_ref(),
        "x",
        "int main() {}",
    )
    .unwrap_err();
    assert!(
        matches!(&error, SetupError::Missing { program, .. } if program == "/nonexistent/g++"),
        "{error}"
    );
}

#[test]
fn a_compile_error_is_reported_in_the_compilers_words() {
    let cache = tempfile::tempdir().unwrap();
    let error = compile_cpp(
        cache.path(),
        "g++".as_ref(),
        "broken",
        "int main() { return undeclared; }\n",
    )
    .unwrap_err();
    let SetupError::Failed { output, .. } = &error else {
        panic!("{error}")
    };
    assert!(output.contains("undeclared"), "{output}");
    let programs = cache.path().join("programs");
    assert_eq!(std::fs::read_dir(&programs).unwrap().count(), 0);
}

#[test]
fn without_network_the_set_up_says_pip_could_not_reach_the_index() {
    let unshare = std::process::Command::new("unshare")
        .args(["-n", "true"])
        .status();
    assert!(
        unshare.is_ok_and(|s| s.success()),
        "this test needs `unshare -n` (util-linux, as root) to take the network away"
    );
    let cache = tempfile::tempdir().unwrap();
    let out = std::process::Command::new("unshare")
        .args(["-n", env!("CARGO_BIN_EXE_raycheck"), "adapter", "trimesh"])
        .env("RAYCHECK_CACHE_DIR", cache.path())
        .env("PIP_RETRIES", "1")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("pip could not reach the package index")
            && stderr(&out).contains("trimesh"),
        "{}",
        stderr(&out)
    );
    // Nothing half made is left where an environment would be.
    let left: Vec<String> = std::fs::read_dir(cache.path().join("python"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(left, ["trimesh.lock"]);
}

/// The `rtree` requirement of the trimesh adapter, with its hashes: one
/// small wheel without dependencies.
fn rtree_requirement() -> String {
    let text = std::fs::read_to_string(Adapter::folder().join("trimesh/requirements.txt")).unwrap();
    let mut lines = text.lines().skip_while(|l| !l.starts_with("rtree=="));
    let first = lines.next().expect("an rtree pin");
    std::iter::once(first)
        .chain(lines.take_while(|l| l.trim_start().starts_with("--hash")))
        .map(|l| format!("{l}\n"))
        .collect()
}

#[test]
fn an_environment_is_made_once_and_made_again_when_damaged() {
    let cache = tempfile::tempdir().unwrap();
    let requirements = rtree_requirement();
    let ensure = || {
        PythonEnv::ensure(cache.path(), "python3".as_ref(), "rtree", &requirements)
            .unwrap_or_else(|e| panic!("{e}"))
    };
    let version = |env: &PythonEnv| {
        let out = std::process::Command::new(env.python())
            .args(["-c", "import rtree; print(rtree.__version__)"])
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", stderr(&out));
        stdout(&out).trim().to_string()
    };
    let env = ensure();
    assert_eq!(version(&env), "1.4.1");
    let marker = env.dir().join("raycheck-requirements.txt");
    let made = std::fs::metadata(&marker).unwrap().modified().unwrap();
    assert_eq!(ensure(), env);
    assert_eq!(
        std::fs::metadata(&marker).unwrap().modified().unwrap(),
        made
    );
    std::fs::remove_file(&marker).unwrap();
    assert_eq!(ensure(), env);
    assert_eq!(version(&env), "1.4.1");
    // Only the environment and its lock are left: no temporary folder.
    let mut left: Vec<String> = std::fs::read_dir(cache.path().join("python"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left.len(), 2, "{left:?}");
    assert_eq!(left[1], "rtree.lock");
    assert!(left[0].starts_with("rtree-"), "{left:?}");
}
