//! The report's sweep section (`raycheck sweep`, see docs/sweep.md): per
//! sampled scene a figure of relMSE and FLIP against samples and against
//! time with the slopes of the fitted power laws; what stratification buys
//! at equal time; ours against Embree beside the noise; per BVH scene each
//! choice's total time of build plus N frames over the cheapest one's;
//! wrong answers against speed; every table of the sweep; and under each
//! figure a paragraph saying what it shows.

use crate::fit::LogLogFit;
use crate::report::plot::{Mark, Plot, Scale, Series};
use crate::report::section::Section;
use crate::results::table::escape_html;
use crate::scene::assets::file_safe;
use crate::sweep::SweepReport;
use crate::sweep::break_even::Cost;
use crate::sweep::bvh_choices::{BvhScene, ChoiceResult};
use crate::sweep::robustness::CATALOGUE;
use crate::sweep::sampled::{CountPoint, SamplerCurve, SceneSweep, Target};
use crate::sweep::tables::{frame_range, slope};
use std::path::{Path, PathBuf};

/// Builds the section, saving its figures under `images`; `caption` is
/// the run's stamp (machine, date, commit, threads).
pub fn section(images: &Path, sweep: &SweepReport, caption: &str) -> anyhow::Result<Section> {
    let mut section = Section::new("sweep", "Error against run time", INTRODUCTION);
    section.table(&sweep.slopes_table());
    section.table(&sweep.references_table());
    for scene in &sweep.sampled {
        let panels = error_panels(scene);
        let name = format!("sweep-{}.svg", file_safe(&scene.scene));
        composite_figure(
            &mut section,
            images,
            &name,
            &format!("{}: error against samples and time", scene.scene),
            &panels,
            &format!("{} {caption}", error_paragraph(scene)),
            caption,
        )?;
    }
    section.table(&sweep.points_table());
    if !sweep.sampled.is_empty() {
        section.figure(
            images,
            "sweep-equal-time.svg",
            &equal_time_plot(&sweep.sampled, caption),
            &format!("{EQUAL_TIME_PARAGRAPH} {caption}"),
        )?;
    }
    section.table(&sweep.equal_time_table());
    section.table(&sweep.equal_error_table());
    if !sweep.sampled.is_empty() {
        section.figure(
            images,
            "sweep-embree.svg",
            &embree_plot(&sweep.sampled, caption),
            &format!("{} {caption}", embree_paragraph(&sweep.sampled)),
        )?;
    }
    section.table(&sweep.embree_table());
    for scene in &sweep.bvh {
        section.figure(
            images,
            &format!("sweep-bvh-{}.svg", file_safe(&scene.scene)),
            &pareto_plot(scene, caption),
            &format!("{} {caption}", pareto_paragraph(scene)),
        )?;
    }
    section.table(&sweep.bvh_table());
    section.figure(
        images,
        "sweep-robustness.svg",
        &robustness_plot(sweep, caption),
        &format!("{ROBUSTNESS_PARAGRAPH} {caption}"),
    )?;
    section.table(&sweep.robustness_table());
    Ok(section.finish())
}

/// Writes the section alone as a page: `out/index.html`, `out/sweep.md`
/// and the figures in `out/images/`; returns the path of `index.html`.
pub fn write_page(out: &Path, sweep: &SweepReport) -> anyhow::Result<PathBuf> {
    let images = out.join("images");
    std::fs::create_dir_all(&images)
        .map_err(|e| anyhow::anyhow!("creating {}: {e}", images.display()))?;
    let section = section(&images, sweep, &sweep.meta.caption())?;
    let write = |name: &str, text: String| {
        let path = out.join(name);
        std::fs::write(&path, text).map_err(|e| anyhow::anyhow!("writing {}: {e}", path.display()))
    };
    write(
        "sweep.md",
        format!("# raycheck sweep\n{}", section.markdown),
    )?;
    write(
        "index.html",
        format!(
            "<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>raycheck sweep</title>\n\
             <style>{}</style></head><body>\n{}</body></html>\n",
            super::style::STYLE,
            section.html
        ),
    )?;
    Ok(out.join("index.html"))
}

const INTRODUCTION: &str = "How a render's error falls as time is spent on it, which BVH pays off after how many frames, and what watertightness costs. Each sampled scene is rendered at 1, 4, 16, … of the samples it takes (light samples, glossy samples, or camera samples each with one light and one glossy sample), with stratified and with independent samples, over several seeds, and measured against its exact image or a converged reference: relMSE (mean over pixels and channels of (I − R)²/(R² + 0.01)) and mean FLIP. Slopes are fitted on log-log axes over every seed's render; −1 for relMSE is what independent samples give; stratified samples fall faster, at −2 on a smooth 2D integrand and −1.5 where edges cross it.";

const EQUAL_TIME_PARAGRAPH: &str = "What stratification buys: at the time each stratified count takes, how many times lower its relMSE is than the independent samples' in the same time (read off their measured curve, or its fitted power law beyond it). Above 1, stratification wins; a ratio growing with time means a steeper slope, a flat one only a constant factor.";

const ROBUSTNESS_PARAGRAPH: &str = "What robustness costs: for each backend, the share of rays whose answer the exact referee calls wrong, against its speed, on the stability catalogue's rays (drawn at the backend's speed over every scene) and on each scene's compare rays. A backend with no wrong ray is drawn at the 95% upper bound of its rate (1 − 0.05^(1/rays), about 3/rays), so the lower it sits the more rays back it. Watertightness costs what separates the points left to right; not having it, what separates them bottom to top.";

/// The relMSE and FLIP panels of one scene: against samples and time.
fn error_panels(scene: &SceneSweep) -> Vec<Plot> {
    let samples = |p: &CountPoint| p.samples as f64;
    let seconds = |p: &CountPoint| p.seconds.mean;
    let rel_mse = |p: &CountPoint| p.rel_mse.mean;
    let flip = |p: &CountPoint| p.flip.mean;
    type Pick = fn(&CountPoint) -> f64;
    type FitOf = fn(&SamplerCurve) -> Option<&LogLogFit>;
    let panels: [(&str, &str, Pick, Pick, FitOf); 4] = [
        ("relMSE", scene.swept.name(), samples, rel_mse, |c| {
            Some(&c.fits.rel_mse_vs_samples)
        }),
        ("relMSE", "wall time, s", seconds, rel_mse, |c| {
            Some(&c.fits.rel_mse_vs_seconds)
        }),
        ("mean FLIP", scene.swept.name(), samples, flip, |c| {
            c.fits.flip_vs_samples.as_ref()
        }),
        ("mean FLIP", "wall time, s", seconds, flip, |c| {
            c.fits.flip_vs_seconds.as_ref()
        }),
    ];
    panels
        .iter()
        .map(|&(metric, x_label, x, y, fit_of)| Plot {
            title: format!("{}: {metric} against {x_label}", scene.scene),
            x_label: x_label.to_string(),
            y_label: format!("{metric} (log)"),
            x_scale: Scale::Log10,
            y_scale: Scale::Log10,
            series: scene
                .samplers
                .iter()
                .map(|curve| Series {
                    name: match fit_of(curve) {
                        Some(fit) => format!("{}: fit k = {}", curve.sampler, slope(fit)),
                        None => format!("{}: no fit", curve.sampler),
                    },
                    points: curve.points.iter().map(|p| (x(p), y(p))).collect(),
                    mark: Mark::LineAndPoints,
                })
                .collect(),
            caption: String::new(),
        })
        .collect()
}

fn error_paragraph(scene: &SceneSweep) -> String {
    let against = match (&scene.target, &scene.reference) {
        (Target::Analytic, _) => {
            "its exact image (Lambert's formula), which no bias of the renderer can share"
                .to_string()
        }
        (_, Some(r)) => format!(
            "a converged reference of {} samples per pixel whose own relMSE ({:.1e}, from its two halves) is {:.0}× below the smallest relMSE swept",
            r.summary.samples, r.summary.rel_mse, r.margin
        ),
        (_, None) => "a reference".to_string(),
    };
    let slopes: Vec<String> = scene
        .samplers
        .iter()
        .map(|c| {
            format!(
                "{} samples^{} (time^{})",
                c.sampler,
                slope(&c.fits.rel_mse_vs_samples),
                slope(&c.fits.rel_mse_vs_seconds)
            )
        })
        .collect();
    let where_ = match scene.swept {
        crate::sweep::swept::SweptCount::PixelSamples => {
            "each with one light sample and one glossy sample"
        }
        _ => "at pixel centres, so nothing else is sampled",
    };
    format!(
        "{}: {} {where_}, {}² pixels, {} seeds per count, against {against}. Top: relMSE, bottom: mean FLIP; left against samples, right against wall time; the points are means over seeds, and each legend gives the slope k of the power law fitted over every seed's render, with its 95% interval. relMSE falls as {}.",
        scene.scene,
        scene.swept.name(),
        scene.resolution,
        scene.seeds,
        slopes.join(" and ")
    )
}

fn equal_time_plot(scenes: &[SceneSweep], caption: &str) -> Plot {
    Plot {
        title: "What stratification buys: independent over stratified relMSE at equal time".into(),
        x_label: "wall time of the stratified render, s".into(),
        y_label: "relMSE ratio, independent / stratified (log)".into(),
        x_scale: Scale::Log10,
        y_scale: Scale::Log10,
        series: scenes
            .iter()
            .map(|s| Series {
                name: s.scene.clone(),
                points: s
                    .equal_time
                    .iter()
                    .map(|r| (r.seconds, r.error_ratio))
                    .collect(),
                mark: Mark::LineAndPoints,
            })
            .collect(),
        caption: caption.to_string(),
    }
}

/// Per scene the relMSE between Embree's image and ours at each count,
/// beside the noise of ours at the same counts (every scene's in one
/// series: what matters is how far below it the differences lie).
fn embree_plot(scenes: &[SceneSweep], caption: &str) -> Plot {
    let noise = Series {
        name: "noise: ours against the target, every scene".into(),
        points: scenes
            .iter()
            .flat_map(|s| &s.embree)
            .map(|d| (d.samples as f64, d.noise_rel_mse))
            .collect(),
        mark: Mark::Points,
    };
    let differences = scenes.iter().map(|s| Series {
        name: format!("{}: Embree against ours", s.scene),
        points: s
            .embree
            .iter()
            .map(|d| (d.samples as f64, d.rel_mse))
            .collect(),
        mark: Mark::LineAndPoints,
    });
    Plot {
        title: "Ours against Embree on the same samples, beside the noise".into(),
        x_label: "samples (of the count each scene sweeps)".into(),
        y_label: "relMSE (log)".into(),
        x_scale: Scale::Log10,
        y_scale: Scale::Log10,
        series: std::iter::once(noise).chain(differences).collect(),
        caption: caption.to_string(),
    }
}

fn embree_paragraph(scenes: &[SceneSweep]) -> String {
    let identical: Vec<&str> = scenes
        .iter()
        .filter(|s| s.embree.iter().all(|d| d.differing_pixels == 0))
        .map(|s| s.scene.as_str())
        .collect();
    let largest = scenes
        .iter()
        .flat_map(|s| &s.embree)
        .map(|d| d.rel_mse / d.noise_rel_mse)
        .fold(0.0, f64::max);
    let ambiguous: u64 = scenes
        .iter()
        .flat_map(|s| &s.embree)
        .map(|d| d.verdicts.ambiguous)
        .sum();
    let disagreements: u64 = scenes
        .iter()
        .flat_map(|s| &s.embree)
        .map(|d| d.verdicts.disagreements)
        .sum();
    let mut text = format!(
        "Ours against Embree MEDIUM with the same seed, sampler and settings, so the same sample sequences: the relMSE between the two images at each count, beside the noise of ours (its relMSE against the target). The difference is at most {largest:.1e} of the noise. Sampling cannot cause it, since both drew the same samples; it comes from hits: the last bits of hit points where both find the same triangle (Embree's Möller–Trumbore test and our watertight one round t, u, v differently), and the rays on which the two disagree: {disagreements} in all, {ambiguous} of them ambiguous (an exact tie, or a one-ulp change of an input flips the exact answer), the others the wrong answers counted in the table below."
    );
    if !identical.is_empty() {
        text += &format!(
            " Identical images (no point on the log axis): {}.",
            identical.join(", ")
        );
    }
    text
}

/// The frame counts the lines are drawn at: 1 to 10⁴, eight a decade.
fn frame_counts() -> Vec<f64> {
    (0..=32).map(|i| 10f64.powf(i as f64 / 8.0)).collect()
}

/// Each choice's total time (build + N frames) over the cheapest
/// choice's at the same N: the frontier's choices touch 1. Drawn for the
/// frontier's choices, then Embree MEDIUM, our wide BVH and our binary SAH
/// of 16 bins (the defaults), up to the plot's eight colours.
fn pareto_plot(scene: &BvhScene, caption: &str) -> Plot {
    let cheapest_somewhere = |i: usize| {
        scene
            .frontier
            .iter()
            .any(|s| s.choice == i && frame_range(s.from_frames, s.to_frames).is_some())
    };
    let mut shown: Vec<usize> = Vec::new();
    for span in &scene.frontier {
        if cheapest_somewhere(span.choice) && !shown.contains(&span.choice) {
            shown.push(span.choice);
        }
    }
    for default in ["Embree MEDIUM", "wide (8-wide SAH)", "SAH, 16 bins"] {
        if let Some(i) = scene.choices.iter().position(|c| c.choice == default)
            && !shown.contains(&i)
        {
            shown.push(i);
        }
    }
    shown.truncate(8);
    let costs: Vec<Cost> = scene.choices.iter().map(ChoiceResult::cost).collect();
    let cheapest = |n: f64| {
        costs
            .iter()
            .map(|c| c.total(n))
            .fold(f64::INFINITY, f64::min)
    };
    Plot {
        title: format!(
            "{}: total time over the cheapest choice's ({}² frames)",
            scene.scene, scene.frame_resolution
        ),
        x_label: "frames rendered N (log)".into(),
        y_label: "(build + N frames) / cheapest (log)".into(),
        x_scale: Scale::Log10,
        y_scale: Scale::Log10,
        series: shown
            .iter()
            .map(|&i| {
                let tag = if cheapest_somewhere(i) {
                    ""
                } else {
                    " (never cheapest)"
                };
                Series {
                    name: format!("{}{tag}", scene.choices[i].choice),
                    points: frame_counts()
                        .into_iter()
                        .map(|n| (n, costs[i].total(n) / cheapest(n)))
                        .collect(),
                    mark: Mark::Line,
                }
            })
            .collect(),
        caption: caption.to_string(),
    }
}

fn pareto_paragraph(scene: &BvhScene) -> String {
    let spans: Vec<String> = scene
        .frontier
        .iter()
        .filter_map(|s| {
            let frames = frame_range(s.from_frames, s.to_frames)?;
            Some(format!(
                "{} at {frames} frames",
                scene.choices[s.choice].choice
            ))
        })
        .collect();
    format!(
        "{} ({} triangles): the total time of building each choice and rendering N frames of the scene's own render at {}², over the cheapest choice's total at that N (build and frame times: medians of the timed runs). At few frames the builds decide; at many, each line levels off at its frame time over the fastest frame time. The choices at 1 form the Pareto frontier: the cheapest in total is {}. Every choice, with the frame count from which it beats the next cheaper build, is in the table below.",
        scene.scene,
        scene.triangles,
        scene.frame_resolution,
        spans.join(", then ")
    )
}

fn robustness_plot(sweep: &SweepReport, caption: &str) -> Plot {
    let mut series: Vec<Series> = Vec::new();
    // (backend, from the catalogue) of each point drawn at its bound.
    let bounded: Vec<(&str, bool)> = sweep
        .robustness
        .points
        .iter()
        .filter(|p| p.zero_wrong_bound.is_some())
        .map(|p| (p.backend.as_str(), p.rays_from == CATALOGUE))
        .collect();
    for backend in sweep
        .robustness
        .points
        .iter()
        .map(|p| p.backend.as_str())
        .fold(Vec::new(), |mut names, n| {
            if !names.contains(&n) {
                names.push(n);
            }
            names
        })
    {
        for catalogue in [true, false] {
            let points: Vec<(f64, f64)> = sweep
                .robustness
                .points
                .iter()
                .filter(|p| p.backend == backend && (p.rays_from == CATALOGUE) == catalogue)
                .map(|p| {
                    (
                        p.mrays_per_second,
                        p.zero_wrong_bound.unwrap_or(p.wrong_rate),
                    )
                })
                .collect();
            if !points.is_empty() {
                let from = if catalogue {
                    CATALOGUE.to_string()
                } else {
                    format!("{} scenes' rays", points.len())
                };
                let bounds = bounded
                    .iter()
                    .filter(|&&(b, c)| b == backend && c == catalogue)
                    .count();
                let note = match bounds {
                    0 => String::new(),
                    n if n == points.len() => " (none wrong: 95% bound)".into(),
                    n => format!(" ({n} with none wrong: 95% bound)"),
                };
                series.push(Series {
                    name: format!("{backend}: {from}{note}"),
                    points,
                    mark: Mark::Points,
                });
            }
        }
    }
    Plot {
        title: "Wrong answers against speed".into(),
        x_label: "Mrays/s (primary, shadow and diffuse rays)".into(),
        y_label: "rays judged wrong, share of all (log)".into(),
        x_scale: Scale::Linear,
        y_scale: Scale::Log10,
        series,
        caption: caption.to_string(),
    }
}

/// Saves `panels` side by side, two to a row, with the run's `stamp` under
/// them, as one SVG under `images`, and shows it with `caption` under it.
fn composite_figure(
    section: &mut Section,
    images: &Path,
    name: &str,
    title: &str,
    panels: &[Plot],
    caption: &str,
    stamp: &str,
) -> anyhow::Result<()> {
    let svgs: Vec<String> = panels.iter().map(Plot::to_svg).collect();
    let size = |svg: &str, attribute: &str| -> f64 {
        svg.split_once(&format!("{attribute}=\""))
            .and_then(|(_, rest)| rest.split_once('"'))
            .and_then(|(value, _)| value.parse().ok())
            .unwrap_or(0.0)
    };
    let column_width = svgs.iter().map(|s| size(s, "width")).fold(0.0, f64::max);
    let row_height = svgs.iter().map(|s| size(s, "height")).fold(0.0, f64::max);
    let rows = svgs.len().div_ceil(2);
    let stamp_height = 20.0;
    let (width, height) = (2.0 * column_width, rows as f64 * row_height + stamp_height);
    let mut svg = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{height}\" \
         viewBox=\"0 0 {width} {height}\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    );
    for (i, panel) in svgs.iter().enumerate() {
        let (x, y) = ((i % 2) as f64 * column_width, (i / 2) as f64 * row_height);
        // A nested <svg> placed at (x, y) keeps each panel's own coordinates.
        svg += &panel.replacen("<svg ", &format!("<svg x=\"{x}\" y=\"{y}\" "), 1);
    }
    svg += &format!(
        "<text x=\"8\" y=\"{:.1}\" font-family=\"sans-serif\" font-size=\"10\" fill=\"#666\">{}</text>\n</svg>\n",
        height - 6.0,
        escape_html(stamp)
    );
    let path = images.join(name);
    std::fs::write(&path, svg).map_err(|e| anyhow::anyhow!("writing {}: {e}", path.display()))?;
    section.markdown += &format!("![{title}](images/{name})\n\n_{caption}_\n\n");
    section.html += &format!(
        "<figure><img class=\"plot\" style=\"width:{width}px;max-width:100%\" src=\"images/{name}\" alt=\"{}\">\
         <figcaption>{}</figcaption></figure>\n",
        escape_html(title),
        escape_html(caption)
    );
    Ok(())
}
