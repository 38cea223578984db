//! The fast BVH (`bvh::wide`) against Embree (ROBUST, MEDIUM) on the compare
//! ray sets, and `raycheck perf`'s JSON.

use crate::support::compare;
use raycheck::backends::BackendName;
use raycheck::perf::measure::Stat;
use raycheck::perf::{self, PerfOptions, PerfReport};
use raycheck::run::Form;

const RESOLUTION: u32 = 192;

fn assert_ours_right(name: &str, resolution: u32) {
    let summary = compare(name, "ours,embree-robust", resolution);
    let context = serde_json::to_string_pretty(&summary).unwrap();
    assert!(
        summary.rays() > resolution as u64 * resolution as u64,
        "{context}"
    );
    let ours = summary.verdicts.backend("ours").unwrap();
    assert_eq!((ours.wrong, ours.t_off), (0, 0), "{context}");
    assert!(
        summary.against_first[0].hit_agreement >= 0.99999,
        "{context}"
    );
}

#[test]
fn fast_bvh_is_never_wrong_against_embree() {
    for name in ["cornell", "monkey", "dragon-11k", "dragon-48k"] {
        assert_ours_right(name, RESOLUTION);
    }
}

#[test]
fn fast_bvh_is_never_wrong_against_embree_on_the_large_dragons() {
    for name in ["dragon-203k", "dragon-871k"] {
        assert_ours_right(name, RESOLUTION);
    }
}

#[test]
fn perf_json_has_every_field_for_every_scene_and_backend() {
    let backends = BackendName::defaults();
    let run = crate::support::run(Form::Quick);
    let options = PerfOptions {
        form: Form::Quick,
        thread_counts: vec![1],
        backends: backends.clone(),
        only_scenes: Vec::new(),
    };
    let report = perf::run(&run, &options, &|_| {}).unwrap();
    // The stamp names our kernel and the ISA Embree reported selecting.
    let kernel = raycheck::bvh::wide::Kernel::detect();
    assert_eq!(report.kernel, kernel.to_string());
    assert!(
        report.embree_isa.contains("(selected, ") && report.embree_isa.ends_with("; asked auto)"),
        "{}",
        report.embree_isa
    );
    assert!(
        report
            .caption()
            .contains(&format!("ours: kernel {kernel} · Embree: isa ")),
        "{}",
        report.caption()
    );
    let json = serde_json::to_value(&report).unwrap();
    let rows = json["rows"].as_array().unwrap();
    assert_eq!(
        rows.len(),
        raycheck::scene::QUICK_SCENES.len() * backends.len()
    );
    for row in rows {
        for key in ["build_ms", "mrays_primary", "mrays_shadow", "mrays_diffuse"] {
            let stat = &row[key];
            let median = stat["median"].as_f64().unwrap_or(f64::NAN);
            assert!(median.is_finite() && median > 0.0, "{key} in {row}");
            assert_eq!(stat["runs"].as_array().unwrap().len(), 3, "{key} in {row}");
        }
        let bytes = row["bytes_per_tri"].as_f64().unwrap_or(f64::NAN);
        assert!(bytes.is_finite() && bytes > 0.0, "{row}");
        assert_eq!(row["threads"], 1, "{row}");
    }
    assert_eq!(report.scaling.len(), backends.len());
    let markdown = report.markdown();
    assert!(markdown.contains("dragon-11k"), "{markdown}");
    assert!(
        markdown.contains("Speed relative to embree-robust"),
        "{markdown}"
    );
    saved_runs_compare_by_their_noise(&report);
}

/// The run saved and loaded again, against doctored copies of itself: one
/// slower beyond its noise, one within it. Only the saved numbers decide.
/// Embree's rows are the yardstick (`perf::baseline`): the others are
/// judged by their ratio to Embree's, run by run, and Embree's own are
/// shown, not judged.
fn saved_runs_compare_by_their_noise(report: &PerfReport) {
    use raycheck::perf::baseline::{Verdict, compare, slower};
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("saved.json");
    std::fs::write(&path, serde_json::to_string(report).unwrap()).unwrap();
    let saved = PerfReport::load(&path).unwrap();
    let yardstick = raycheck::backends::embree::EMBREE.to_string();
    let is_yardstick = |c: &raycheck::perf::baseline::Change| c.backend == yardstick;
    // Every run of two throughputs of every backend but the yardstick
    // scaled by what `factor` gives for its stat and the yardstick's: the
    // spread stays, the level moves.
    let doctor = |factor: &dyn Fn(&Stat, &Stat) -> f64| {
        let mut run = saved.clone();
        for row in &mut run.rows {
            if row.backend == yardstick {
                continue;
            }
            let by = saved.row(&row.scene, row.threads, &yardstick).unwrap();
            for (stat, by) in [
                (&mut row.mrays_primary, &by.mrays_primary),
                (&mut row.mrays_shadow, &by.mrays_shadow),
            ] {
                let scale = factor(stat, by);
                *stat = Stat::of(stat.runs.iter().map(|v| v * scale).collect());
            }
        }
        compare(&saved, &run)
    };
    let itself = doctor(&|_, _| 1.0);
    assert!(itself.iter().all(|c| c.verdict == Verdict::WithinNoise));
    for c in &itself {
        assert_eq!(c.judged, !is_yardstick(c), "{c:?}");
        assert_eq!(c.relative_to.is_some(), !is_yardstick(c), "{c:?}");
    }
    // Every new ratio to the yardstick a thousandth of the saved min over
    // its max: a drop of more than e^6.9 on log scale, beyond Holm's bound
    // for any spread of three runs short of a factor of ten.
    let ratios = |stat: &Stat, by: &Stat| -> Vec<f64> {
        stat.runs.iter().zip(&by.runs).map(|(v, b)| v / b).collect()
    };
    let lower = doctor(&|stat, by| {
        let r = ratios(stat, by);
        let (min, max) = r.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &x| {
            (lo.min(x), hi.max(x))
        });
        1e-3 * min / max
    });
    let judged_rows = report
        .rows
        .iter()
        .filter(|r| r.backend != yardstick)
        .count();
    assert_eq!(slower(&lower), 2 * judged_rows, "{lower:?}");
    assert!(
        lower
            .iter()
            .filter(|c| is_yardstick(c))
            .all(|c| c.verdict == Verdict::WithinNoise),
        "{lower:?}"
    );
    // A part in a million is within it.
    let within = doctor(&|_, _| 1.0 - 1e-6);
    assert!(
        within.iter().all(|c| c.verdict != Verdict::Slower),
        "{within:?}"
    );
    std::fs::write(&path, "{}").unwrap();
    let error = PerfReport::load(&path).unwrap_err();
    assert!(format!("{error:#}").contains("not a run saved by raycheck perf"));
}
