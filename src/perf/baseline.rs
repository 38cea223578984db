//! `raycheck perf --baseline FILE`: every metric of this run against a
//! saved run, judged by both runs' spread.
//!
//! A metric's change is a speed ratio (above 1 is faster: old over new
//! build time, new over old throughput) of the geometric means of the
//! runs, tested by Welch's t-test on the runs' logs (`welch`), with its 95%
//! interval. A hundred-odd metrics are judged at once, so a few of
//! unchanged code would fall outside their own 95% intervals by chance:
//! the verdicts hold the chance of calling any of them changed to 5%
//! together, by Holm's step-down procedure over all judged metrics (Holm
//! 1979, "A simple sequentially rejective multiple test procedure",
//! Scandinavian Journal of Statistics 6). A metric is slower beyond its
//! noise when Holm rejects no change and its ratio is below 1.
//!
//! Embree is the yardstick when both runs measured it on the same scene
//! and thread count (for the rays, through the same binding,
//! [`raycheck_reference::BINDING_REVISION`]): its code is the same in
//! every run, so its own change is the machine's (another tenant, another
//! clock), and every other
//! backend's metric is then judged as its ratio to Embree's, run by run
//! (`measure` interleaves the backends, so run `i` of each was measured
//! side by side). Embree's own changes are shown, each by its own test at
//! 5%, not judged.

use super::PerfReport;
use super::measure::PerfRow;
use super::welch::Welch;
use crate::backends::embree::EMBREE;
use crate::results::{Cell, Table, Tone};
use serde::Serialize;

/// The build-time metric's name.
const BUILD: &str = "build ms";
/// Each interval's coverage.
const CONFIDENCE: f64 = 0.95;
/// The chance, over all judged metrics together, of calling a metric of
/// unchanged code changed.
const FAMILY_ERROR: f64 = 0.05;

/// What one metric did between the saved run and this one.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    Faster,
    WithinNoise,
    Slower,
}

/// One metric of one scene, thread count and backend, before and after.
#[derive(Clone, Debug, Serialize)]
pub struct Change {
    pub scene: String,
    pub threads: usize,
    pub backend: String,
    pub metric: &'static str,
    /// Geometric means of the runs.
    pub before: f64,
    pub after: f64,
    /// Speed ratio of the geometric means: above 1 is faster.
    pub speed: f64,
    /// The 95% interval of `speed`.
    pub low: f64,
    pub high: f64,
    /// Welch's two-sided p-value of no change (1 where a run has fewer
    /// than two values: nothing to judge by).
    pub p_value: f64,
    pub verdict: Verdict,
    /// The backend `before` and `after` are ratios to, run by run: the
    /// yardstick, for every backend judged against it.
    pub relative_to: Option<String>,
    /// Whether the verdict counts towards the exit status: not for the
    /// yardstick's own metrics, which measure the machine.
    pub judged: bool,
}

/// How many of `changes` are slower beyond their noise: what makes
/// `perf --baseline` exit 1.
pub fn slower(changes: &[Change]) -> usize {
    changes
        .iter()
        .filter(|c| c.judged && c.verdict == Verdict::Slower)
        .count()
}

/// What differs between the two runs besides the code: the machine, our
/// kernel, Embree's instruction set, how queries crossed to Embree. Ratios
/// across any of them compare those too, so the table says so above its
/// verdicts.
pub fn unlike(before: &PerfReport, after: &PerfReport) -> Vec<String> {
    let binding = |run: &PerfReport| format!("revision {}", run.embree_binding);
    [
        (
            "machine",
            before.meta.machine.clone(),
            after.meta.machine.clone(),
        ),
        ("our kernel", before.kernel.clone(), after.kernel.clone()),
        (
            "Embree's isa",
            before.embree_isa.clone(),
            after.embree_isa.clone(),
        ),
        ("Embree's binding", binding(before), binding(after)),
    ]
    .into_iter()
    .filter(|(_, old, new)| old != new)
    .map(|(what, old, new)| format!("{what} {old} then, {new} now"))
    .collect()
}

/// Every metric measured in both runs (same scene, threads and backend),
/// against the yardstick where both runs have it, with the verdicts of
/// Holm's procedure over the judged ones (see the module).
pub fn compare(before: &PerfReport, after: &PerfReport) -> Vec<Change> {
    let yardstick = EMBREE.to_string();
    let mut changes = Vec::new();
    for new in &after.rows {
        let Some(old) = before.row(&new.scene, new.threads, &new.backend) else {
            continue;
        };
        // The yardstick's runs in both runs, for every other backend.
        let is_yardstick = new.backend == yardstick;
        let by = match (
            before.row(&new.scene, new.threads, &yardstick),
            after.row(&new.scene, new.threads, &yardstick),
        ) {
            (Some(old_by), Some(new_by)) if !is_yardstick => Some(samples(old_by, new_by)),
            _ => None,
        };
        for (index, (metric, higher_is_better, old_runs, new_runs)) in
            samples(old, new).into_iter().enumerate()
        {
            let mut change = match by {
                Some(by) if same_embree(metric, before, after) => {
                    let (_, _, old_by, new_by) = by[index];
                    let mut change = change(
                        new,
                        metric,
                        higher_is_better,
                        &run_ratios(old_runs, old_by),
                        &run_ratios(new_runs, new_by),
                    );
                    change.relative_to = Some(yardstick.clone());
                    change
                }
                _ => change(new, metric, higher_is_better, old_runs, new_runs),
            };
            // Embree's own row measures the machine (across bindings, the
            // binding too): shown, never judged.
            change.judged = !is_yardstick;
            changes.push(change);
        }
    }
    let judged: Vec<usize> = (0..changes.len()).filter(|&i| changes[i].judged).collect();
    let p_values: Vec<f64> = judged.iter().map(|&i| changes[i].p_value).collect();
    for (i, changed) in judged.into_iter().zip(holm(&p_values, FAMILY_ERROR)) {
        let change = &mut changes[i];
        change.verdict = verdict(changed, change.speed);
    }
    changes
}

/// Whether both runs timed the same Embree for `metric`: always for the
/// builds, which do not cross the binding; for the rays, when both runs
/// crossed through the same binding.
fn same_embree(metric: &str, before: &PerfReport, after: &PerfReport) -> bool {
    metric == BUILD || before.embree_binding == after.embree_binding
}

/// Which of the hypotheses with `p_values` Holm's step-down procedure
/// rejects at family-wise error `alpha`: sorted from the smallest p, the
/// `k`-th (from 0) is rejected while its p is at most `alpha / (m - k)`.
fn holm(p_values: &[f64], alpha: f64) -> Vec<bool> {
    let mut order: Vec<usize> = (0..p_values.len()).collect();
    order.sort_by(|&a, &b| p_values[a].total_cmp(&p_values[b]));
    let mut rejected = vec![false; p_values.len()];
    let m = p_values.len();
    for (k, &i) in order.iter().enumerate() {
        if p_values[i] > alpha / (m - k) as f64 {
            break;
        }
        rejected[i] = true;
    }
    rejected
}

fn verdict(changed: bool, speed: f64) -> Verdict {
    match (changed, speed < 1.0) {
        (false, _) => Verdict::WithinNoise,
        (true, true) => Verdict::Slower,
        (true, false) => Verdict::Faster,
    }
}

/// Run `i` of a backend over run `i` of the yardstick, for every run both
/// have.
fn run_ratios(runs: &[f64], yardstick: &[f64]) -> Vec<f64> {
    runs.iter()
        .zip(yardstick)
        .map(|(run, by)| run / by)
        .collect()
}

type Samples<'a> = (&'static str, bool, &'a [f64], &'a [f64]);

fn samples<'a>(old: &'a PerfRow, new: &'a PerfRow) -> [Samples<'a>; 4] {
    [
        (BUILD, false, &old.build_ms.runs, &new.build_ms.runs),
        (
            "primary Mrays/s",
            true,
            &old.mrays_primary.runs,
            &new.mrays_primary.runs,
        ),
        (
            "shadow Mrays/s",
            true,
            &old.mrays_shadow.runs,
            &new.mrays_shadow.runs,
        ),
        (
            "diffuse Mrays/s",
            true,
            &old.mrays_diffuse.runs,
            &new.mrays_diffuse.runs,
        ),
    ]
}

/// One metric's change, its verdict by its own test at `FAMILY_ERROR`
/// (`compare` replaces the judged ones' by Holm's).
fn change(
    row: &PerfRow,
    metric: &'static str,
    higher_is_better: bool,
    old: &[f64],
    new: &[f64],
) -> Change {
    let (before, after) = (geometric_mean(old), geometric_mean(new));
    let speed = if higher_is_better {
        after / before
    } else {
        before / after
    };
    let welch = Welch::of(old, new);
    // On log scale a ratio is a difference, and lower-is-better flips it.
    let sign = if higher_is_better { 1.0 } else { -1.0 };
    let (low, high) = welch.map_or((0.0, f64::INFINITY), |w| {
        let (low, high) = w.interval(CONFIDENCE);
        let (low, high) = (sign * low, sign * high);
        (low.min(high).exp(), low.max(high).exp())
    });
    let p_value = welch.map_or(1.0, |w| w.p_value());
    Change {
        scene: row.scene.clone(),
        threads: row.threads,
        backend: row.backend.clone(),
        metric,
        before,
        after,
        speed,
        low,
        high,
        p_value,
        verdict: verdict(p_value <= FAMILY_ERROR, speed),
        relative_to: None,
        judged: true,
    }
}

fn geometric_mean(values: &[f64]) -> f64 {
    (values.iter().map(|v| v.ln()).sum::<f64>() / values.len() as f64).exp()
}

/// The changes as a table, slower ones toned bad and faster ones good.
pub fn table(changes: &[Change], before: &PerfReport, after: &PerfReport) -> Table {
    let unlike = unlike(before, after);
    let judged = changes.iter().filter(|c| c.judged).count();
    let warning = if unlike.is_empty() {
        String::new()
    } else {
        format!(
            ". Not like for like ({}): the ratios measure that change as well as the code's",
            unlike.join("; ")
        )
    };
    let mut table = Table::new(
        &format!(
            "Against the saved run of {} (commit {}): speed ratio of the geometric means of the runs, above 1 is faster, with its {:.0}% interval and Welch's p-value of no change; the verdicts hold the chance of any false call among the {judged} judged metrics to {:.0}% (Holm); a metric \"÷ {EMBREE}\" is the ratio to Embree's in the same runs, which cancels the machine's own drift{warning}",
            before.meta.date,
            before.meta.commit,
            CONFIDENCE * 100.0,
            FAMILY_ERROR * 100.0,
        ),
        &[
            "scene", "threads", "backend", "metric", "before", "after", "speed", "interval", "p",
            "verdict",
        ],
        &after.caption(),
    );
    for c in changes {
        let (tone, word) = match c.verdict {
            Verdict::Faster => (Tone::Good, "faster"),
            Verdict::WithinNoise => (Tone::Plain, "within noise"),
            Verdict::Slower => (Tone::Bad, "slower"),
        };
        let (tone, word) = match (c.judged, same_embree(c.metric, before, after)) {
            (true, _) => (tone, word.to_string()),
            (false, true) => (Tone::Plain, format!("{word} (yardstick: the machine)")),
            (false, false) => (
                Tone::Plain,
                format!("{word} (not judged: its binding changed)"),
            ),
        };
        let metric = match &c.relative_to {
            Some(yardstick) => format!("{} ÷ {yardstick}", c.metric),
            None => c.metric.to_string(),
        };
        table.push([
            Cell::from(c.scene.as_str()),
            c.threads.to_string().into(),
            c.backend.as_str().into(),
            metric.into(),
            format!("{:.2}", c.before).into(),
            format!("{:.2}", c.after).into(),
            Cell::new(format!("{:.3}", c.speed), tone),
            format!("{:.3}–{:.3}", c.low, c.high).into(),
            format!("{:.1e}", c.p_value).into(),
            Cell::new(word, tone),
        ]);
    }
    table
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::perf::fixtures;

    fn row(scale: f64, jitter: &[f64]) -> PerfRow {
        fixtures::row("s", "ours", scale, jitter)
    }

    fn report(rows: Vec<PerfRow>) -> PerfReport {
        fixtures::report(rows, "d", "c")
    }

    const JITTER: [f64; 7] = [1.0, 1.02, 0.97, 1.01, 0.99, 1.03, 0.98];

    #[test]
    fn a_run_against_itself_is_within_noise() {
        let run = report(vec![row(1.0, &JITTER)]);
        let changes = compare(&run, &run);
        assert_eq!(changes.len(), 4);
        for c in &changes {
            assert_eq!(c.verdict, Verdict::WithinNoise, "{c:?}");
            assert_eq!(c.speed, 1.0);
            assert!(c.low < 1.0 && c.high > 1.0, "{c:?}");
        }
    }

    #[test]
    fn a_slower_run_beyond_its_noise_is_flagged_and_one_within_is_not() {
        let saved = report(vec![row(1.0, &JITTER)]);
        // 20% less throughput: far beyond a 3% spread.
        let slower = compare(&saved, &report(vec![row(0.8, &JITTER)]));
        let flagged: Vec<&str> = slower
            .iter()
            .filter(|c| c.verdict == Verdict::Slower)
            .map(|c| c.metric)
            .collect();
        assert_eq!(
            flagged,
            ["primary Mrays/s", "shadow Mrays/s", "diffuse Mrays/s"]
        );
        // 0.5% less, and the runs in another order: within the 3% spread.
        let mut shuffled = JITTER;
        shuffled.reverse();
        let within = compare(&saved, &report(vec![row(0.995, &shuffled)]));
        assert!(
            within.iter().all(|c| c.verdict == Verdict::WithinNoise),
            "{within:?}"
        );
        let faster = compare(&saved, &report(vec![row(1.25, &JITTER)]));
        assert!(faster[1..].iter().all(|c| c.verdict == Verdict::Faster));
    }

    /// The band counts the saved run's spread too: a noisy saved run
    /// against a tight new one 10% slower is within the noise (the saved
    /// mean could as well have been 20% lower), where an interval from
    /// the new run's spread alone would call it slower.
    #[test]
    fn the_noise_band_counts_the_saved_runs_spread() {
        let noisy = [1.0, 0.6, 1.4, 0.8, 1.2, 0.7, 1.3];
        let tight = [1.0, 1.001, 0.999, 1.0, 1.0005, 0.9995, 1.0];
        let changes = compare(
            &report(vec![row(1.0, &noisy)]),
            &report(vec![row(0.9, &tight)]),
        );
        let primary = changes
            .iter()
            .find(|c| c.metric == "primary Mrays/s")
            .unwrap();
        let speed = 0.9 * geometric_mean(&tight) / geometric_mean(&noisy);
        assert!((primary.speed - speed).abs() < 1e-9, "{primary:?}");
        assert_eq!(primary.verdict, Verdict::WithinNoise, "{primary:?}");
        assert!(primary.low < 0.8 && primary.high > 1.0, "{primary:?}");
        // The other way round: a tight saved run and a noisy new one.
        let reversed = compare(
            &report(vec![row(1.0, &tight)]),
            &report(vec![row(0.9, &noisy)]),
        );
        assert!(
            reversed[1..]
                .iter()
                .all(|c| c.verdict == Verdict::WithinNoise)
        );
    }

    /// Holm's procedure worked by hand: sorted, 0.005 ≤ 0.05/4 and
    /// 0.01 ≤ 0.05/3 are rejected, then 0.03 > 0.05/2 stops it, and 0.04
    /// with it, though both are below 0.05 alone.
    #[test]
    fn holm_steps_down_until_a_p_value_passes_its_bound() {
        assert_eq!(
            holm(&[0.01, 0.04, 0.03, 0.005], 0.05),
            [true, false, false, true]
        );
        assert_eq!(holm(&[], 0.05), Vec::<bool>::new());
    }

    /// Among 120 metrics, one whose own p-value is below 1% is what chance
    /// gives unchanged code, and is within the noise; the same change in a
    /// run of 4 metrics is slower.
    #[test]
    fn a_lone_small_change_among_many_metrics_is_within_noise() {
        let scenes: Vec<String> = (0..30).map(|i| format!("s{i}")).collect();
        let run = |last: f64| {
            let rows = scenes.iter().enumerate().map(|(i, scene)| {
                let scale = if i == 0 { last } else { 1.0 };
                fixtures::row(scene, "ours", scale, &JITTER)
            });
            report(rows.collect())
        };
        let primary = |changes: &[Change]| {
            changes
                .iter()
                .find(|c| c.scene == "s0" && c.metric == "primary Mrays/s")
                .cloned()
                .unwrap()
        };
        let changes = compare(&run(1.0), &run(0.96));
        assert_eq!(changes.len(), 120);
        let lone = primary(&changes);
        assert!(lone.high < 1.0 && lone.p_value < 0.01, "{lone:?}");
        assert_eq!(slower(&changes), 0, "{changes:?}");
        let alone = |run: PerfReport| report(run.rows.into_iter().take(1).collect());
        let changes = compare(&alone(run(1.0)), &alone(run(0.96)));
        assert_eq!(primary(&changes).verdict, Verdict::Slower);
    }

    #[test]
    fn a_saved_run_from_another_machine_kernel_or_isa_is_named_as_unlike() {
        let saved = report(vec![row(1.0, &JITTER)]);
        let mut now = saved.clone();
        assert!(unlike(&saved, &now).is_empty());
        assert!(!table(&[], &saved, &now).title.contains("Not like for like"));
        now.meta.machine = "n".into();
        now.kernel = "avx2".into();
        assert_eq!(
            unlike(&saved, &now),
            ["machine m then, n now", "our kernel k then, avx2 now"]
        );
        now.embree_isa = "f".into();
        let title = table(&[], &saved, &now).title;
        assert!(
            title.contains("Not like for like (machine m then, n now; our kernel k then, avx2 now; Embree's isa e then, f now)"),
            "{title}"
        );
    }

    /// Both backends' rows of one run: ours at `ours` times Embree's speed,
    /// Embree's scaled by `machine`, both with the run-by-run `jitter` (a
    /// busy neighbour slows both backends of a run alike).
    fn side_by_side(ours: f64, machine: f64, jitter: &[f64]) -> PerfReport {
        report(vec![
            fixtures::row("s", "ours", ours * machine, jitter),
            fixtures::row("s", "embree", machine, jitter),
        ])
    }

    fn judged_slower(changes: &[Change]) -> Vec<&'static str> {
        changes
            .iter()
            .filter(|c| c.judged && c.verdict == Verdict::Slower)
            .map(|c| c.metric)
            .collect()
    }

    /// A machine 20% slower in the new run slows Embree as much as ours:
    /// judged against Embree, ours has not changed, and Embree's own
    /// slowdown is shown but not judged.
    #[test]
    fn the_machines_drift_cancels_against_the_yardstick() {
        let changes = compare(
            &side_by_side(1.0, 1.0, &JITTER),
            &side_by_side(1.0, 0.8, &JITTER),
        );
        assert_eq!(slower(&changes), 0, "{changes:?}");
        let ours: Vec<&Change> = changes.iter().filter(|c| c.backend == "ours").collect();
        assert_eq!(ours.len(), 4);
        for c in ours {
            assert_eq!(c.relative_to.as_deref(), Some("embree"), "{c:?}");
            assert!(c.judged && c.verdict == Verdict::WithinNoise, "{c:?}");
        }
        let embree = changes
            .iter()
            .find(|c| c.backend == "embree" && c.metric == "primary Mrays/s")
            .unwrap();
        assert!(
            !embree.judged && embree.verdict == Verdict::Slower,
            "{embree:?}"
        );
        assert_eq!(embree.relative_to, None);
        // Without Embree in the runs, the same drift reads as ours slower.
        let alone = |run: PerfReport| report(run.rows.into_iter().take(1).collect());
        let raw = compare(
            &alone(side_by_side(1.0, 1.0, &JITTER)),
            &alone(side_by_side(1.0, 0.8, &JITTER)),
        );
        assert_eq!(slower(&raw), 3, "{raw:?}");
    }

    /// Ours 10% slower against Embree is a regression, even when each run's
    /// spread of raw speeds (a noisy machine) is far wider than 10%: the
    /// run-by-run ratio cancels what both backends of a run shared.
    #[test]
    fn a_regression_against_the_yardstick_is_caught_through_shared_noise() {
        let noisy = [1.0, 0.6, 1.4, 0.8, 1.2, 0.7, 1.3];
        let changes = compare(
            &side_by_side(1.0, 1.0, &noisy),
            &side_by_side(0.9, 1.0, &noisy),
        );
        assert_eq!(
            judged_slower(&changes),
            ["primary Mrays/s", "shadow Mrays/s", "diffuse Mrays/s"]
        );
        let table = table(
            &changes,
            &side_by_side(1.0, 1.0, &noisy),
            &side_by_side(0.9, 1.0, &noisy),
        );
        let text = table.to_text();
        assert!(text.contains("primary Mrays/s ÷ embree"), "{text}");
        assert!(
            text.contains("within noise (yardstick: the machine)"),
            "{text}"
        );
    }

    /// A saved run whose queries crossed to Embree another way timed
    /// another Embree: ours' rays are judged by their own speeds then, its
    /// builds still against Embree's, and the change is named.
    #[test]
    fn embree_through_another_binding_is_no_yardstick() {
        let saved = side_by_side(1.0, 1.0, &JITTER);
        let mut now = report(vec![
            fixtures::row("s", "ours", 1.0, &JITTER),
            fixtures::row("s", "embree", 1.4, &JITTER),
        ]);
        // Through one binding, Embree 1.4 times as fast is ours slower.
        assert_eq!(slower(&compare(&saved, &now)), 3);
        now.embree_binding += 1;
        let changes = compare(&saved, &now);
        assert_eq!(slower(&changes), 0, "{changes:?}");
        for c in changes.iter().filter(|c| c.backend == "ours") {
            let by_embree = c.relative_to.is_some();
            assert_eq!(by_embree, c.metric == BUILD, "{c:?}");
        }
        let binding = format!(
            "Embree's binding revision {} then, revision {} now",
            saved.embree_binding, now.embree_binding
        );
        assert_eq!(unlike(&saved, &now), [binding]);
        let text = table(&changes, &saved, &now).to_text();
        assert!(
            text.contains("faster (not judged: its binding changed)"),
            "{text}"
        );
    }

    #[test]
    fn rows_missing_from_either_run_are_left_out() {
        let mut other = row(1.0, &JITTER);
        other.scene = "elsewhere".into();
        let changes = compare(&report(vec![row(1.0, &JITTER)]), &report(vec![other]));
        assert!(changes.is_empty());
    }
}
