//! The report's section on third-party tracers: obvhs, bvh and parry3d
//! beside ours and Embree on every scene and every stability case, their
//! wrong answers with rays to replay them, and their speed beside Embree.

use super::ReportData;
use super::section::Section;
use crate::backends::{BackendName, EMBREE_MEDIUM};
use crate::check::Judgement;
use crate::results::agreement::{AnswerRecord, SampleRecord};
use crate::results::{Cell, Table};
use crate::stability::CaseResult;

const INTRO: &str = "The BVH crates Rust users pick, each behind the same trait as ours: obvhs \
(its CWBVH built with PLOC), bvh (svenstaro's, with its own ray/triangle test) and parry3d \
(TriMesh ray casts, the ray caster of Rapier and Bevy). Each adapter passes rays and returns \
hits in the crate's own conventions, converted where they differ and documented in \
docs/tracers.md; a part of an answer a crate does not give (parry3d's u, v) is n/a, never \
counted right or wrong. Every scene's rays go through ours, the three crates and Embree robust \
at once, and the stability catalogue runs them all; every ray on which two differ, and 1% of \
the others, is judged exactly. Look at the wrong columns, and replay any ray below.";

/// At most this many replayable wrong answers per crate.
const SAMPLES_PER_CRATE: usize = 6;

pub fn section(data: &ReportData) -> Section {
    let caption = data.meta.caption();
    let mut section = Section::new("tracers", "Third-party tracers", INTRO);
    let names: Vec<String> = data
        .tracers
        .first()
        .map(|t| t.backends.clone())
        .unwrap_or_default();
    section.table(&overview(data, &names, &caption));
    section.table(&per_scene(data, &names, &caption));
    section.table(&replayable(data, &caption));
    section.finish()
}

/// Sums `f` of the backend named `name` over every case.
fn over_cases(cases: &[CaseResult], name: &str, f: fn(&CaseResult, usize) -> Option<u64>) -> u64 {
    cases
        .iter()
        .filter_map(|c| {
            let index = c.verdicts.backends.iter().position(|b| b.name == name)?;
            f(c, index)
        })
        .sum()
}

/// The speed of `name` relative to Embree MEDIUM on the largest scene
/// timed, at the most threads: primary, shadow and diffuse throughput.
fn speed(data: &ReportData, name: &str) -> Option<[f64; 3]> {
    let perf = &data.performance;
    let embree = BackendName::Embree(EMBREE_MEDIUM).to_string();
    let largest = perf.headline()?;
    let row = perf.row(&largest.scene, largest.threads, name)?;
    let base = perf.row(&largest.scene, largest.threads, &embree)?;
    let r = row.ratios(base);
    Some([r[1], r[2], r[3]])
}

fn overview(data: &ReportData, names: &[String], caption: &str) -> Table {
    let largest = data.performance.headline().map_or("-".to_string(), |r| {
        format!("{}, {} thread(s)", r.scene, r.threads)
    });
    let speed_header = format!("speed vs Embree MEDIUM, primary / shadow / diffuse ({largest})");
    let mut table = Table::new(
        &format!(
            "Every backend over {} scenes and the {} stability catalogue",
            data.tracers.len(),
            if data.stability_quick {
                "quick"
            } else {
                "full"
            }
        ),
        &[
            "backend",
            "scene rays wrong",
            "scene rays t off",
            "NaN outputs",
            "catalogue rays wrong",
            "rays undecided",
            "catalogue leaks",
            "meshes it could not build over",
            &speed_header,
        ],
        caption,
    );
    for name in names {
        let scene_sum = |f: fn(&crate::results::BackendTally) -> u64| -> u64 {
            data.tracers
                .iter()
                .filter_map(|t| t.verdicts.backend(name))
                .map(f)
                .sum()
        };
        table.push([
            Cell::from(name.as_str()),
            Cell::wrong_count(scene_sum(|b| b.wrong)),
            Cell::wrong_count(scene_sum(|b| b.t_off)),
            Cell::wrong_count(
                scene_sum(|b| b.nan_outputs)
                    + over_cases(&data.stability, name, |c, i| {
                        Some(c.verdicts.backends[i].nan_outputs)
                    }),
            ),
            Cell::wrong_count(over_cases(&data.stability, name, |c, i| {
                Some(c.verdicts.backends[i].wrong)
            })),
            Cell::undecided_count(
                scene_sum(|b| b.undecided)
                    + over_cases(&data.stability, name, |c, i| {
                        Some(c.verdicts.backends[i].undecided)
                    }),
            ),
            Cell::wrong_count(over_cases(&data.stability, name, |c, i| c.leaks(i))),
            Cell::wrong_count(over_cases(&data.stability, name, |c, i| {
                Some(c.verdicts.backends[i].build_failures)
            })),
            speed(data, name).map_or_else(
                || Cell::from("-"),
                |[p, s, d]| format!("{p:.2} / {s:.2} / {d:.2}").into(),
            ),
        ]);
    }
    table
}

fn per_scene(data: &ReportData, names: &[String], caption: &str) -> Table {
    let wrong: Vec<String> = names.iter().map(|n| format!("wrong: {n}")).collect();
    let mut headers = vec!["scene", "triangles", "rays", "judged"];
    headers.extend(wrong.iter().map(String::as_str));
    let mut table = Table::new("Wrong answers per scene, in rays", &headers, caption);
    for t in &data.tracers {
        let mut row = vec![
            Cell::from(t.scene.as_str()),
            t.triangles.to_string().into(),
            t.verdicts.rays.to_string().into(),
            t.verdicts.judged.to_string().into(),
        ];
        row.extend(
            names
                .iter()
                .map(|n| Cell::wrong_count(t.verdicts.backend(n).map_or(0, |b| b.wrong))),
        );
        table.push(row);
    }
    table
}

fn answer_text(answer: &AnswerRecord) -> String {
    match answer {
        AnswerRecord::Hit { prim, t, .. } => format!("triangle {prim} at t = {t}"),
        AnswerRecord::Miss => "miss".into(),
        AnswerRecord::Occluded { occluded } => {
            if *occluded {
                "occluded".into()
            } else {
                "not occluded".into()
            }
        }
    }
}

/// For each crate, its first wrong answers over the scenes, with the ray's
/// bits and the answer the referee accepts.
fn replayable(data: &ReportData, caption: &str) -> Table {
    let mut table = Table::new(
        "Wrong answers to replay: the ray as f32 bits (origin xyz, direction xyz, tnear, tfar), the crate's answer, and an admissible one",
        &[
            "backend",
            "scene",
            "rays",
            "query",
            "ray bits",
            "its answer",
            "admissible answer",
        ],
        caption,
    );
    for name in super::THIRD_PARTY.map(|n| n.to_string()) {
        let samples = data
            .tracers
            .iter()
            .flat_map(|t| t.samples.iter().map(move |s| (t.scene.as_str(), s)));
        for (scene, sample) in samples
            .filter(|(_, s)| wrong_for(s, &name))
            .take(SAMPLES_PER_CRATE)
        {
            let theirs = sample.answers.iter().find(|a| a.backend == name);
            let right = sample.answers.iter().find(|a| a.judgement.is_admissible());
            table.push([
                Cell::from(name.as_str()),
                scene.into(),
                sample.ray_set.name().into(),
                sample.query.into(),
                sample.ray.bits.join(" ").into(),
                Cell::new(
                    theirs.map_or("-".into(), |a| answer_text(&a.answer)),
                    crate::results::Tone::Bad,
                ),
                right
                    .map_or("-".into(), |a| {
                        format!("{} ({})", answer_text(&a.answer), a.backend)
                    })
                    .into(),
            ]);
        }
    }
    table
}

fn wrong_for(sample: &SampleRecord, name: &str) -> bool {
    sample
        .answers
        .iter()
        .any(|a| a.backend == name && a.judgement == Judgement::Wrong)
}
