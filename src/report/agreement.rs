//! The report's first section: every scene's rays through our three BVHs
//! and Embree at once, judged exactly, and ours against Embree shown as
//! two renders and their difference.

use super::ReportData;
use super::measure::{REFERENCE, SceneMeasurements};
use super::section::Section;
use crate::backends::ours::OURS;
use crate::results::pixels::{MAP_DECADES, RELATIVE_BOUND};
use crate::results::{Cell, RunMeta, Table};
use std::path::Path;

const INTRO: &str = "Each scene's primary rays, a shadow ray per light and a mirror-reflection \
ray from every primary hit, asked of our three BVHs (wide, SAH, median split) and of Embree \
4.4 (MEDIUM, and MEDIUM with ROBUST) at once. Every ray on which two backends differ, and 1% \
of the others, goes to the exact referee: an answer is wrong when it is not the exact answer \
for the ray's f32 inputs, nor for any one-ulp change of one input or one vertex coordinate. \
Look at the wrong columns: a green zero means that backend gave no wrong answer.";

/// Builds the section and writes each scene's renders and difference map
/// into `images`.
pub fn section(images: &Path, data: &ReportData) -> anyhow::Result<Section> {
    let caption = data.meta.caption();
    let mut section = Section::new("agreement", "Agreement with Embree", INTRO);
    section.table(&summary_table(&data.scenes, &caption));
    for s in &data.scenes {
        write_images(images, s, &data.meta)?;
        section.subheading(&format!(
            "{} ({} triangles; {})",
            s.scene,
            s.triangles,
            s.features.join(", ")
        ));
        section.images(
            &[
                (format!("{}.png", s.scene), format!("{}, ours", s.scene)),
                (
                    format!("{}-embree.png", s.scene),
                    format!("{}, Embree", s.scene),
                ),
                (
                    format!("{}-difference.png", s.scene),
                    format!("{}, difference", s.scene),
                ),
            ],
            &figure_caption(s, &caption),
        );
        section.table(&s.agreement.table(&caption));
    }
    Ok(section.finish())
}

fn write_images(images: &Path, s: &SceneMeasurements, meta: &RunMeta) -> anyhow::Result<()> {
    let stamp = |what: &str| meta.stamp(&format!("{}, {what}", s.scene));
    for ext in ["png", "exr"] {
        s.ours_image.save_stamped(
            &images.join(format!("{}.{ext}", s.scene)),
            &stamp(&format!("ours ({OURS})")),
        )?;
        s.embree_image.save_stamped(
            &images.join(format!("{}-embree.{ext}", s.scene)),
            &stamp(&format!("Embree ({REFERENCE})")),
        )?;
    }
    s.difference_image.save_stamped(
        &images.join(format!("{}-difference.png", s.scene)),
        &stamp("|ours - Embree|, log scale"),
    )?;
    Ok(())
}

/// Every scene's verdicts per backend, in one table.
fn summary_table(scenes: &[SceneMeasurements], caption: &str) -> Table {
    let mut table = Table::new(
        "Every scene: wrong answers per backend, in rays",
        &[
            "scene",
            "triangles",
            "rays",
            "judged",
            "ambiguous",
            "backend",
            "wrong",
            "undecided",
            "t off",
            "NaN outputs",
        ],
        caption,
    );
    for s in scenes {
        let v = &s.agreement.verdicts;
        for b in &v.backends {
            table.push([
                Cell::from(s.scene.as_str()),
                s.triangles.to_string().into(),
                v.rays.to_string().into(),
                v.judged.to_string().into(),
                v.ambiguous.to_string().into(),
                b.name.as_str().into(),
                Cell::wrong_count(b.wrong),
                Cell::undecided_count(b.undecided),
                Cell::wrong_count(b.t_off),
                Cell::wrong_count(b.nan_outputs),
            ]);
        }
    }
    table
}

fn figure_caption(s: &SceneMeasurements, caption: &str) -> String {
    let p = &s.pixels;
    let faults = p.first_wrong + p.unexplained;
    let conclusion = if faults == 0 {
        "So ours and Embree differ by floating-point noise alone, except where a ray has two \
         right answers or Embree's is wrong."
            .to_string()
    } else {
        format!("{faults} pixels are ours to answer for.")
    };
    format!(
        "{name} at {res}×{res}. Left ours ({OURS}), middle Embree ({REFERENCE}), right their \
         difference per pixel: black where identical (or invisible, below 1e-5), then log10 of \
         the largest channel difference relative to the pixel, on a viridis ramp from \
         1e-{decades} (dark) to 1 (yellow), red beyond the f32 bound ({bound} relative). \
         {differing} of {pixels} pixels differ, the largest by {largest:.2e} (linear radiance); \
         {beyond} exceed the bound. Each was traced again through both backends at once, along \
         each render's own rays: {ambiguous_primary} have a primary ray, {ambiguous_shadow} a \
         shadow ray and {ambiguous_secondary} a reflection ray that the two answered \
         differently and the referee found ambiguous (a silhouette, a shadow edge or a \
         reflection edge); {divergent} asked different secondary rays from hit points a few \
         ulps apart and got different answers, each right (a shadow ray grazing an edge from \
         one point and not from the other); at {second_wrong} Embree answered a ray wrongly, \
         at {first_wrong} ours did, and {unexplained} are unexplained. {conclusion} {caption}",
        name = s.scene,
        res = s.resolution,
        decades = MAP_DECADES,
        bound = RELATIVE_BOUND,
        differing = p.differing,
        pixels = p.pixels,
        largest = p.largest,
        beyond = p.beyond_bound,
        ambiguous_primary = p.ambiguous_primary,
        ambiguous_shadow = p.ambiguous_shadow,
        ambiguous_secondary = p.ambiguous_secondary,
        divergent = p.divergent_rays,
        second_wrong = p.second_wrong,
        first_wrong = p.first_wrong,
        unexplained = p.unexplained,
    )
}
