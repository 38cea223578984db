//! A stability case through files, as a tracer outside the process sees
//! it: exported as a bundle of (mesh, rays) pairs, traced by a backend,
//! judged beside the built-in backends, it gives the very verdicts the
//! case gives in process.

use crate::cli::{raycheck, stderr, stdout};
use crate::support::workers;
use raycheck::backends::{BackendName, DEFAULT_BACKENDS};
use raycheck::check::Answer;
use raycheck::exchange::{Bundle, HitsFile, bundle, case_batches, judge_bundle, trace_bundle};
use raycheck::results::Verdicts;
use raycheck::stability::{CASES, Context, run_catalogue};
use std::path::Path;

/// The case's verdicts in process, over the default backends.
fn in_process(case: &str) -> Verdicts {
    let pool = workers(None);
    let backends = BackendName::parse_list(DEFAULT_BACKENDS).unwrap();
    let context = Context {
        backends: &backends,
        build: pool.build_context(),
        quick: true,
        recorder: None,
    };
    let results = pool.install(|| run_catalogue(&context, Some(case)));
    assert_eq!(results.len(), 1, "{case}");
    assert_eq!(results[0].panics, 0, "{:?}", results[0].failure);
    results[0].verdicts.clone()
}

/// The verdicts on hits named `name` judged beside the default backends
/// must be the in-process ones, the hits' column that of `traced`.
fn assert_same(through_files: &Verdicts, in_process: &Verdicts, name: &str, traced: &str) {
    let context = format!("{through_files:#?}\nin process: {in_process:#?}");
    let counts = |v: &Verdicts| (v.rays, v.judged, v.disagreements, v.ambiguous);
    assert_eq!(counts(through_files), counts(in_process), "{context}");
    assert_eq!(
        through_files.backends[1..],
        in_process.backends[..],
        "{context}"
    );
    let mut hits = through_files.backends[0].clone();
    assert_eq!(hits.name, name, "{context}");
    hits.name = traced.to_string();
    assert_eq!(Some(&hits), in_process.backend(traced), "{context}");
}

#[test]
fn every_case_judges_the_same_through_files_as_in_process() {
    let dir = tempfile::tempdir().unwrap();
    let pool = workers(None);
    let beside = BackendName::parse_list(DEFAULT_BACKENDS).unwrap();
    for (case, _) in CASES {
        let batches = pool.install(|| case_batches(case, pool.build_context(), false));
        if case == "nan_and_inf" {
            let error = batches.expect_err("NaN vertices cannot be exported");
            assert!(error.to_string().contains("cannot be exported"), "{error}");
            continue;
        }
        let batches = batches.unwrap();
        let expected = in_process(case);
        let folder = dir.path().join(case);
        let manifest = bundle::write(&folder, case, false, &batches).unwrap();
        assert_eq!(manifest.pairs.len(), batches.len());
        let bundle = Bundle::open(&folder).unwrap();
        // Embree MEDIUM's hits everywhere (the most faults to count); ours
        // and ROBUST's too on the case of 160 placements.
        let traced: &[&str] = match case {
            "scale_and_offset" => &["embree", "ours", "embree-robust"],
            _ => &["embree"],
        };
        for name in traced {
            let hits = dir.path().join(format!("{case}-{name}"));
            let backend: BackendName = name.parse().unwrap();
            pool.install(|| trace_bundle(&bundle, &backend, pool.build_context(), &hits))
                .unwrap();
            let summary = pool
                .install(|| judge_bundle(&bundle, &hits, "hits", &beside, pool.build_context()))
                .unwrap();
            assert_same(&summary.verdicts, &expected, "hits", name);
        }
    }
}

/// Wrong any-hit answers in a bundle's hits are judged and counted: the
/// any-hit rays files are asked, not only the closest-hit ones.
#[test]
fn a_wrong_occlusion_in_a_bundle_is_counted() {
    let dir = tempfile::tempdir().unwrap();
    let pool = workers(None);
    let case = "closed_mesh_leaks";
    let batches = pool
        .install(|| case_batches(case, pool.build_context(), false))
        .unwrap();
    let folder = dir.path().join(case);
    bundle::write(&folder, case, false, &batches).unwrap();
    let bundle = Bundle::open(&folder).unwrap();
    let hits = dir.path().join("hits");
    pool.install(|| {
        trace_bundle(
            &bundle,
            &"ours".parse().unwrap(),
            pool.build_context(),
            &hits,
        )
    })
    .unwrap();
    // Every ray starts inside a closed sphere and must hit it: saying
    // "not occluded" is wrong, whatever one-ulp change is tried.
    let pair = &bundle.manifest.pairs[2];
    let path = bundle::hits_path(&hits, &pair.any_hit);
    let mut file = HitsFile::read(&path).unwrap();
    let planted = [3, 50, 400];
    for i in planted {
        assert_eq!(file.answers[i], Answer::Occluded(true));
        file.answers[i] = Answer::Occluded(false);
    }
    file.write(&path).unwrap();
    let beside = BackendName::parse_list(DEFAULT_BACKENDS).unwrap();
    let summary = pool
        .install(|| judge_bundle(&bundle, &hits, "hits", &beside, pool.build_context()))
        .unwrap();
    assert_eq!(
        summary.pairs[2].verdicts.backends[0].wrong, 3,
        "{summary:#?}"
    );
    assert_eq!(summary.verdicts.backends[0].wrong, 3, "{summary:#?}");
    assert_eq!(summary.verdicts.backends[1].wrong, 0, "{summary:#?}");
}

/// `rays`, `trace` and `judge` on a bundle from the command line: the
/// JSON's verdicts are the case's.
#[test]
fn the_round_trip_runs_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("leaks");
    let hits = dir.path().join("embree-hits");
    let json = dir.path().join("verdicts.json");
    let path = |p: &Path| p.to_str().unwrap().to_string();
    let run = |args: &[&str]| {
        let out = raycheck(args);
        assert!(
            out.status.code() == Some(0) || out.status.code() == Some(1),
            "{args:?}: {}{}",
            stdout(&out),
            stderr(&out)
        );
        out
    };
    run(&["rays", "--set", "closed_mesh", "--out", &path(&folder)]);
    run(&[
        "trace",
        &path(&folder),
        "--backend",
        "embree",
        "--out",
        &path(&hits),
    ]);
    let out = run(&[
        "judge",
        &path(&folder),
        &path(&hits),
        "--json",
        &path(&json),
    ]);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let mut through_files = summary["verdicts"].clone();
    let expected = serde_json::to_value(in_process("closed_mesh_leaks")).unwrap();
    let backends = through_files["backends"].as_array_mut().unwrap();
    let hits = backends.remove(0);
    assert_eq!(hits["name"], "embree-hits", "{summary}");
    assert_eq!(through_files, expected, "{summary}");
    let embree = expected["backends"]
        .as_array()
        .unwrap()
        .iter()
        .find(|b| b["name"] == "embree")
        .unwrap();
    let mut renamed = hits.clone();
    renamed["name"] = "embree".into();
    assert_eq!(&renamed, embree, "{summary}");
    // Exit 1 exactly when the judged hits have a wrong answer.
    let faults = ["wrong", "t_off", "nan_outputs"]
        .iter()
        .map(|k| hits[*k].as_u64().unwrap())
        .sum::<u64>();
    assert_eq!(
        out.status.code(),
        Some(i32::from(faults > 0)),
        "{}",
        stdout(&out)
    );
}

/// The one-mesh merge of scale_and_offset (all 160 placements in one mesh,
/// every ray against all of it) is a scene of its own: nested, nearly
/// coincident geometry where a ray meets up to thousands of triangles, and
/// where the referee's one-ulp search, made change by change from scratch,
/// grew with the square of them. Embree MEDIUM's answers there, and misses
/// where rays hit, are each decided within 32 exact evaluations per nearby
/// triangle (half the default budget; the costliest take about 16).
#[test]
fn the_referee_decides_the_crowded_one_mesh_scene_at_a_bounded_cost() {
    use raycheck::backends::embree::EMBREE;
    use raycheck::check::exact::Oracle;
    use raycheck::check::{Judgement, Referee};
    use rayon::prelude::*;
    let pool = workers(None);
    let case = "scale_and_offset";
    let batches = pool
        .install(|| case_batches(case, pool.build_context(), false))
        .unwrap();
    let merged = raycheck::exchange::merged(case, false, &batches);
    let embree = EMBREE.build(&merged.mesh, pool.build_context()).unwrap();
    let oracle = Oracle::new(&merged.mesh);
    let crowded: Vec<_> = merged
        .rays
        .iter()
        .filter(|ray| (256..8192).contains(&oracle.candidates(ray).len()))
        .collect();
    assert!(crowded.len() > 200, "{} crowded rays", crowded.len());
    let referee = Referee::with_budget(&merged.mesh, 32);
    let judged: Vec<Judgement> = pool.install(|| {
        crowded
            .par_iter()
            .flat_map_iter(|ray| {
                let answers = [
                    Answer::Closest(embree.intersect(ray)),
                    Answer::Closest(None),
                    Answer::Occluded(false),
                ];
                referee.judge_all(ray, &answers)
            })
            .collect()
    });
    let count = |j: Judgement| judged.iter().filter(|&&k| k == j).count();
    assert_eq!(count(Judgement::Undecided), 0, "{judged:?}");
    assert!(
        count(Judgement::Wrong) > 0 && count(Judgement::Admissible) > 0,
        "{judged:?}"
    );
}
