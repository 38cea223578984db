//! The report's section on third-party tracers: the crates (obvhs, bvh,
//! parry3d) and the programs (tracers in other languages, through files)
//! beside ours and Embree on every scene and every stability case, their
//! wrong answers with rays to replay them, the crates' speed beside
//! Embree, and what each program did.

use super::section::Section;
use super::{ProgramPart, ReportData};
use crate::backends::embree::EMBREE;
use crate::check::Judgement;
use crate::results::agreement::{AnswerRecord, SampleRecord};
use crate::results::{Cell, Table, Tone};
use crate::scene;
use crate::stability::CaseResult;

const INTRO: &str = "The BVH crates Rust users pick, each behind the same trait as ours: obvhs \
(its CWBVH built with PLOC), bvh (svenstaro's, with its own ray/triangle test) and parry3d \
(TriMesh ray casts, the ray caster of Rapier and Bevy); and tracers in other languages run as \
programs that read a mesh and a rays file and write a hits file (the adapters in adapters/, \
or any program a tracers file names): their rays are recorded from the checked backend's run, \
traced in batches and their answers replayed. Each adapter passes rays and returns hits in the \
tracer's own conventions, converted where they differ and documented in docs/tracers.md; a \
part of an answer a tracer does not give (parry3d's u, v) is n/a, never counted right or \
wrong. Every scene's rays go through ours, the third-party tracers and Embree robust at once, \
and the stability catalogue runs them all; every ray on which two differ, and 1% of the \
others, is judged exactly. Look at the wrong columns, and replay any ray below.";

/// At most this many replayable wrong answers per crate.
const SAMPLES_PER_CRATE: usize = 6;

pub fn section(data: &ReportData) -> Section {
    let caption = data.meta.caption();
    let mut section = Section::new("tracers", "Third-party tracers", INTRO);
    let names = &data.tracer_backends;
    section.table(&overview(data, names, &caption));
    section.table(&per_scene(data, names, &caption));
    section.table(&replayable(data, &caption));
    programs(&mut section, data, &caption);
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
    let embree = EMBREE.to_string();
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
        // A slow program runs only the quick catalogue.
        let catalogue = |count: u64| {
            let ran = data
                .stability
                .iter()
                .any(|c| c.verdicts.backends.iter().any(|b| &b.name == name));
            if ran {
                Cell::wrong_count(count)
            } else {
                Cell::from("not run")
            }
        };
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
            catalogue(over_cases(&data.stability, name, |c, i| {
                Some(c.verdicts.backends[i].wrong)
            })),
            Cell::undecided_count(
                scene_sum(|b| b.undecided)
                    + over_cases(&data.stability, name, |c, i| {
                        Some(c.verdicts.backends[i].undecided)
                    }),
            ),
            catalogue(over_cases(&data.stability, name, |c, i| c.leaks(i))),
            catalogue(over_cases(&data.stability, name, |c, i| {
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
        row.extend(names.iter().map(|n| match t.verdicts.backend(n) {
            Some(b) => Cell::wrong_count(b.wrong),
            None => Cell::from("not run"),
        }));
        table.push(row);
    }
    table
}

/// What each program did in each part, which ones failed and why, and
/// the scenes a slow one leaves out.
fn programs(section: &mut Section, data: &ReportData, caption: &str) {
    let parts: Vec<&ProgramPart> = data
        .programs
        .iter()
        .filter(|p| !p.runs.is_empty())
        .collect();
    if parts.is_empty() {
        return;
    }
    section.subheading("Programs");
    let mut table = Table::new(
        "What each program traced, through files (wall time shown, not compared: it counts the program's start and its file reading and writing)",
        &[
            "part", "program", "meshes", "rays", "batches", "wall s", "k rays/s", "status",
        ],
        caption,
    );
    let mut failures = Vec::new();
    for part in &parts {
        for run in &part.runs {
            let w = &run.workload;
            let rate = if w.seconds > 0.0 {
                format!("{:.0}", w.rays as f64 / w.seconds / 1e3)
            } else {
                "-".into()
            };
            table.push([
                Cell::from(part.part.as_str()),
                run.name.as_str().into(),
                w.meshes.to_string().into(),
                w.rays.to_string().into(),
                w.batches.to_string().into(),
                format!("{:.1}", w.seconds).into(),
                rate.into(),
                match &run.error {
                    Some(_) => Cell::new("failed", Tone::Bad),
                    None => Cell::new("ran", Tone::Good),
                },
            ]);
            if let Some(error) = &run.error {
                failures.push(format!("{} in {}: {error}", run.name, part.part));
            }
        }
    }
    section.table(&table);
    for failure in failures {
        section.paragraph(&format!(
            "Left out, the rest of the report run without it: {failure}"
        ));
    }
    let scale: Vec<(&str, usize)> = data
        .tracers
        .iter()
        .filter(|t| scene::SCALE_SCENES.contains(&t.scene.as_str()))
        .map(|t| (t.scene.as_str(), t.triangles))
        .collect();
    for (scene, triangles) in &scale {
        section.paragraph(&format!(
            "{scene} is traced by ours and Embree robust alone, as in the performance \
             section: every crate and program would hold its own tree and copy of its \
             {triangles} triangles."
        ));
    }
    let traced: Vec<(&str, &[String])> = data
        .tracers
        .iter()
        .map(|t| (t.scene.as_str(), t.backends.as_slice()))
        .collect();
    for name in &data.tracer_backends {
        let is_program = data
            .programs
            .iter()
            .any(|p| p.runs.iter().any(|r| &r.name == name));
        let (ran, left) = scenes_of(&traced, name);
        if !is_program || left.is_empty() {
            continue;
        }
        section.paragraph(&format!(
            "{name} traces slowly, so the report runs it on {} of the {} scenes ({}), \
             in every form; `raycheck compare SCENE --backends ours,{name}` runs it \
             on any other.",
            ran.len(),
            ran.len() + left.len(),
            ran.join(", ")
        ));
        if !data.stability_quick {
            section.paragraph(&format!(
                "It runs the quick stability catalogue only: the full one's millions \
                 of rays would take it hours. raycheck report, or raycheck stability \
                 --quick --backends ours,embree-robust,{name}, judges it there."
            ));
        }
    }
}

/// Of the scenes traced (each with the backends that traced it), those
/// `name` traced and those it left out, the scale scenes (traced by ours
/// and Embree alone) counted in neither.
fn scenes_of<'a>(traced: &[(&'a str, &[String])], name: &str) -> (Vec<&'a str>, Vec<&'a str>) {
    let (mut ran, mut left) = (Vec::new(), Vec::new());
    for &(scene, backends) in traced {
        if scene::SCALE_SCENES.contains(&scene) {
            continue;
        }
        if backends.iter().any(|b| b == name) {
            ran.push(scene);
        } else {
            left.push(scene);
        }
    }
    (ran, left)
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
    for name in super::third_party().iter().map(|n| n.to_string()) {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A program left out of the scale scene, as every third-party tracer
    /// is, left out nothing; one left out of a large scene did.
    #[test]
    fn a_scene_left_out_is_one_beyond_the_scale_scenes() {
        let all = ["ours", "mitsuba-scalar", "trimesh"].map(String::from);
        let fast = ["ours", "mitsuba-scalar"].map(String::from);
        let alone = ["ours", "embree-robust"].map(String::from);
        let traced: [(&str, &[String]); 3] = [
            ("monkey", &all),
            ("dragon-871k", &fast),
            ("dragon-14m", &alone),
        ];
        assert_eq!(
            scenes_of(&traced, "mitsuba-scalar"),
            (vec!["monkey", "dragon-871k"], vec![])
        );
        assert_eq!(
            scenes_of(&traced, "trimesh"),
            (vec!["monkey"], vec!["dragon-871k"])
        );
    }
}
