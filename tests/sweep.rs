//! `raycheck sweep` on small inputs: a quick sweep of the analytic scene
//! and a reference-measured one, checked against what the integrands
//! predict, and its JSON against the keys docs/sweep.md documents.

use raycheck::backends::BackendName;
use raycheck::parallel::InstructionSets;
use raycheck::run::{Form, RunContext, RunOptions};
use raycheck::stability::{self, CaseResult};
use raycheck::sweep::sampled::{SceneSweep, Target};
use raycheck::sweep::swept::SweptCount;
use raycheck::sweep::{SweepOptions, SweepReport, run_with_catalogue};
use serde_json::Value;
use std::sync::OnceLock;

/// The quick sweep of the analytic scene and cornell-area, with the quick
/// catalogue's `grid_edges` case for the robustness part (run once for
/// every test here).
fn quick_sweep() -> &'static SweepReport {
    static SWEEP: OnceLock<SweepReport> = OnceLock::new();
    SWEEP.get_or_init(|| {
        let options = SweepOptions {
            scenes: vec!["analytic-area".into(), "cornell-area".into()],
            quick: true,
        };
        let run = RunContext::new(RunOptions {
            threads: Some(2),
            form: Form::Quick,
            sets: InstructionSets::default(),
        })
        .unwrap();
        run_with_catalogue(&run, &options, &grid_edges(&run), &|_| {}).unwrap()
    })
}

fn grid_edges(run: &RunContext) -> Vec<CaseResult> {
    stability::run(run, &BackendName::defaults(), Some("grid_edges"))
}

fn scene<'a>(sweep: &'a SweepReport, name: &str) -> &'a SceneSweep {
    sweep.sampled.iter().find(|s| s.scene == name).unwrap()
}

/// The slope a sampler's relMSE must fall at against samples where the
/// integrand is smooth (the analytic scene: a uniform light over a plane,
/// nothing occluded). Independent samples: each pixel's variance is σ²/n,
/// so relMSE, a fixed weighting of those variances, goes exactly as
/// n⁻¹. Stratified (jittered) samples on a smooth 2D integrand: each of
/// the n cells of side n^-1/2 contributes a variance of order
/// |∇f|²·(1/n)/n², n of them: n⁻². Both within ±0.15, the band the
/// project asks of the independent slope.
const SMOOTH_SLOPES: [(&str, f64); 2] = [("stratified", -2.0), ("independent", -1.0)];
const BAND: f64 = 0.15;

#[test]
fn the_analytic_scene_falls_at_the_derived_slopes_with_no_bias_floor() {
    let analytic = scene(quick_sweep(), "analytic-area");
    assert_eq!(analytic.target, Target::Analytic);
    assert_eq!(analytic.swept, SweptCount::LightSamples);
    assert!(analytic.reference.is_none());
    for (curve, (name, expected)) in analytic.samplers.iter().zip(SMOOTH_SLOPES) {
        assert_eq!(curve.sampler, name);
        let fit = &curve.fits.rel_mse_vs_samples;
        assert!(
            (fit.slope - expected).abs() <= BAND,
            "{name}: slope {fit:?}, expected {expected}"
        );
        // No floor: the last step, down to the smallest error swept, falls
        // at the same slope. Against a biased target it would flatten out.
        let [.., a, b] = curve.points.as_slice() else {
            panic!("too few counts")
        };
        let last =
            (b.rel_mse.mean / a.rel_mse.mean).ln() / (b.samples as f64 / a.samples as f64).ln();
        assert!(
            (last - expected).abs() <= BAND,
            "{name}: last step {last}, expected {expected}"
        );
    }
    // One sample of a stratum is an independent sample: the same image.
    let firsts: Vec<f64> = analytic
        .samplers
        .iter()
        .map(|c| c.points[0].rel_mse.mean)
        .collect();
    assert_eq!(firsts[0], firsts[1]);
}

#[test]
fn stratification_wins_at_equal_time_where_the_slope_is_steeper() {
    let analytic = scene(quick_sweep(), "analytic-area");
    let largest = analytic.samplers[0].points.last().unwrap().samples;
    // At the largest count (64 = 4³) the slopes predict, each factor 4 of
    // samples worth 16× for stratified and 4× for independent, an error
    // ratio of about 4³ = 64 at equal samples; timing noise moves the
    // time axis by far less than the factor 4 that would take away.
    let last = analytic.equal_time.last().unwrap();
    assert_eq!(last.stratified_samples, largest);
    assert!(last.error_ratio > 4.0, "{last:?}");
    let last = analytic.equal_error.last().unwrap();
    assert_eq!(last.independent_samples, largest);
    assert!(last.speedup > 1.0, "{last:?}");
}

#[test]
fn a_rendered_reference_is_converged_ten_times_below_the_sweep() {
    let area = scene(quick_sweep(), "cornell-area");
    assert_eq!(area.target, Target::Reference);
    let reference = area.reference.as_ref().unwrap();
    assert!(reference.converged_enough, "{reference:?}");
    assert!(reference.summary.rel_mse * 10.0 <= reference.smallest_swept_rel_mse);
    // The penumbrae make the integrand discontinuous: stratified samples
    // fall faster than independent ones but not as fast as on a smooth one.
    let [stratified, independent] = [0, 1].map(|i| area.samplers[i].fits.rel_mse_vs_samples.slope);
    assert!(
        stratified < independent - 0.3,
        "{stratified} vs {independent}"
    );
    assert!(stratified > -2.0 - BAND, "{stratified}");
    assert!((independent + 1.0).abs() <= BAND, "{independent}");
}

#[test]
fn ours_and_embree_differ_by_hits_not_by_noise() {
    for scene in &quick_sweep().sampled {
        assert_eq!(scene.embree.len(), scene.samplers[0].points.len());
        for d in &scene.embree {
            let [embree, ours] = [0, 1].map(|i| &d.verdicts.backends[i]);
            assert_eq!(
                (embree.name.as_str(), ours.name.as_str()),
                ("embree", "ours")
            );
            assert_eq!(ours.wrong, 0, "{}: {d:?}", scene.scene);
            // Same samples: what differs is a hit point's last bits, or a
            // ray whose answer a one-ulp change flips; never the noise.
            assert!(
                d.rel_mse < 1e-6 * d.noise_rel_mse,
                "{}: {} against noise {}",
                scene.scene,
                d.rel_mse,
                d.noise_rel_mse
            );
        }
    }
}

#[test]
fn every_bvh_choice_is_measured_and_the_frontier_covers_all_frame_counts() {
    let sweep = quick_sweep();
    assert_eq!(sweep.bvh.len(), 2);
    for scene in &sweep.bvh {
        assert_eq!(scene.choices.len(), 7);
        for c in &scene.choices {
            assert!(c.build_ms.median >= 0.0 && c.frame_ms.median > 0.0, "{c:?}");
            assert!(c.sah_cost > 0.0 && c.bytes.is_some_and(|b| b > 0), "{c:?}");
        }
        let spans = &scene.frontier;
        assert_eq!(spans[0].from_frames, 0.0);
        assert_eq!(spans.last().unwrap().to_frames, None);
        for pair in spans.windows(2) {
            assert_eq!(pair[0].to_frames, Some(pair[1].from_frames));
        }
    }
}

#[test]
fn robustness_points_cover_every_backend_on_the_catalogue_and_each_scene() {
    let points = &quick_sweep().robustness.points;
    for backend in ["ours", "embree", "embree-robust"] {
        for from in ["analytic-area", "cornell-area", "stability catalogue"] {
            let p = points
                .iter()
                .find(|p| p.backend == backend && p.rays_from == from)
                .unwrap_or_else(|| panic!("{backend} on {from} missing"));
            assert!(p.rays > 0 && p.mrays_per_second > 0.0, "{p:?}");
        }
    }
    let catalogue = |backend: &str| {
        points
            .iter()
            .find(|p| p.backend == backend && p.rays_from == "stability catalogue")
            .unwrap()
    };
    // The grid's shared edges: ours is watertight, Embree's default leaks.
    assert_eq!(catalogue("ours").wrong, 0);
    assert!(catalogue("ours").zero_wrong_bound.is_some());
    assert!(catalogue("embree").wrong > 0);
}

/// Every key path `docs/sweep.md` documents, as written in its key
/// tables: `a.b[].c`.
fn documented_keys() -> Vec<String> {
    let docs =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/sweep.md")).unwrap();
    docs.lines()
        .filter_map(|l| {
            l.strip_prefix("| `")?
                .split_once('`')
                .map(|(k, _)| k.to_string())
        })
        .collect()
}

/// Every path of `value`'s object keys, arrays written `[]`.
fn key_paths(value: &Value, prefix: &str, out: &mut std::collections::BTreeSet<String>) {
    match value {
        Value::Object(map) => {
            for (key, v) in map {
                let path = if prefix.is_empty() {
                    key.clone()
                } else {
                    format!("{prefix}.{key}")
                };
                out.insert(path.clone());
                key_paths(v, &path, out);
            }
        }
        Value::Array(items) => {
            for v in items {
                key_paths(v, &format!("{prefix}[]"), out);
            }
        }
        _ => {}
    }
}

#[test]
fn the_json_holds_exactly_the_documented_keys() {
    let json = serde_json::to_value(quick_sweep()).unwrap();
    let mut present = std::collections::BTreeSet::new();
    key_paths(&json, "", &mut present);
    let documented = documented_keys();
    assert!(documented.len() > 50, "{documented:?}");
    let missing: Vec<&String> = documented
        .iter()
        .filter(|k| !present.contains(*k))
        .collect();
    assert!(
        missing.is_empty(),
        "documented but not in the JSON: {missing:?}"
    );
    let undocumented: Vec<&String> = present.iter().filter(|k| !documented.contains(k)).collect();
    assert!(
        undocumented.is_empty(),
        "in the JSON but not documented: {undocumented:?}"
    );
}

#[test]
fn an_unknown_scene_is_an_error_naming_it() {
    let out = crate::cli::raycheck(&["sweep", "no-such-scene", "--quick"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(crate::cli::stderr(&out).contains("no-such-scene"));
}
