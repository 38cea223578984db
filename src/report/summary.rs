//! The summary at the top of the page: what the report found, at a glance,
//! read from the same [`ReportData`] as the sections below it. Each number
//! carries a `data-summary` key in the HTML, so a test can hold it against
//! `report.json`.

use super::ReportData;
use crate::backends::BackendName;
use crate::backends::ours::OURS;
use crate::results::Tone;
use crate::results::table::escape_html;

/// One number of the summary.
#[derive(Clone, Debug, PartialEq)]
pub struct Item {
    /// The `data-summary` key.
    pub key: String,
    pub label: String,
    pub value: String,
    pub tone: Tone,
    /// The section that holds the numbers it sums up.
    pub section: &'static str,
}

/// The summary: groups of items, each group a line of boxes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Summary {
    pub groups: Vec<(String, Vec<Item>)>,
}

fn count(key: String, label: String, value: u64, section: &'static str) -> Item {
    Item {
        key,
        label,
        value: value.to_string(),
        tone: if value == 0 { Tone::Good } else { Tone::Bad },
        section,
    }
}

/// A fitted slope, to two decimals, as the summary and the test read it.
pub fn slope_text(slope: f64) -> String {
    format!("{slope:.2}")
}

/// Ours over `baseline`'s median, to two decimals, as the summary and the
/// test both read it.
pub fn ratio_text(ratio: f64) -> String {
    format!("{ratio:.2}×")
}

impl Summary {
    pub fn of(data: &ReportData) -> Self {
        let mut summary = Summary::default();
        summary.agreement(data);
        summary.speed(data);
        summary.stability(data);
        summary.tracers(data);
        summary.convergence(data);
        summary
    }

    /// The fitted slope of relMSE against samples, per sampled scene and
    /// sampler.
    fn convergence(&mut self, data: &ReportData) {
        let items = data
            .sweep
            .sampled
            .iter()
            .flat_map(|scene| {
                scene.samplers.iter().map(move |curve| Item {
                    key: format!("slope-{}-{}", scene.scene, curve.sampler),
                    label: format!("relMSE ~ samples^k, {}, {}", scene.scene, curve.sampler),
                    value: slope_text(curve.fits.rel_mse_vs_samples.slope),
                    tone: Tone::Plain,
                    section: "sweep",
                })
            })
            .collect();
        self.groups
            .push(("Convergence: error against samples".into(), items));
    }

    fn agreement(&mut self, data: &ReportData) {
        let rays: u64 = data.scenes.iter().map(|s| s.agreement.verdicts.rays).sum();
        let mut items = vec![Item {
            key: "rays-checked".into(),
            label: format!(
                "rays asked of every backend on {} scenes",
                data.scenes.len()
            ),
            value: rays.to_string(),
            tone: Tone::Plain,
            section: "agreement",
        }];
        let names: Vec<String> = data
            .scenes
            .first()
            .map(|s| s.agreement.backends.clone())
            .unwrap_or_default();
        for name in names {
            let faults: u64 = data
                .scenes
                .iter()
                .filter_map(|s| s.agreement.verdicts.backend(&name))
                .map(|b| b.faults())
                .sum();
            items.push(count(
                format!("wrong-{name}"),
                format!("rays {name} answered wrongly"),
                faults,
                "agreement",
            ));
        }
        let ours_to_blame: u64 = data
            .scenes
            .iter()
            .map(|s| (s.pixels.first_wrong + s.pixels.unexplained) as u64)
            .sum();
        items.push(count(
            "pixels-ours-to-blame".into(),
            "pixels of ours beyond f32 noise from Embree's, at a wrong ray of ours or unexplained"
                .into(),
            ours_to_blame,
            "agreement",
        ));
        self.groups.push(("Every hit checked".into(), items));
    }

    fn speed(&mut self, data: &ReportData) {
        let perf = &data.performance;
        let ours = OURS.to_string();
        let Some(largest) = perf.headline() else {
            return;
        };
        let Some(row) = perf.row(&largest.scene, largest.threads, &ours) else {
            return;
        };
        let mut items = Vec::new();
        for goals in &crate::perf::GOALS {
            let baseline = goals.baseline.to_string();
            let Some(base) = perf.row(&largest.scene, largest.threads, &baseline) else {
                continue;
            };
            let ratios = row.ratios(base);
            for (i, metric) in ["build", "primary", "shadow", "diffuse"].iter().enumerate() {
                items.push(Item {
                    key: format!("speed-{metric}-{baseline}"),
                    label: format!("ours / {baseline}, {metric}"),
                    value: ratio_text(ratios[i]),
                    tone: if ratios[i] >= goals.minimum[i] {
                        Tone::Good
                    } else {
                        Tone::Bad
                    },
                    section: "performance",
                });
            }
        }
        let title = format!(
            "Speed against Embree ({}, {} triangles, {} thread(s), {}; above 1× is faster)",
            largest.scene,
            largest.triangles,
            largest.threads,
            perf.instruction_sets()
        );
        self.groups.push((title, items));
    }

    fn stability(&mut self, data: &ReportData) {
        let cases = &data.stability;
        let of = |name: &str, f: fn(&crate::stability::CaseResult, usize) -> Option<u64>| {
            cases
                .iter()
                .filter_map(|c| {
                    let index = c.verdicts.backends.iter().position(|b| b.name == name)?;
                    f(c, index)
                })
                .sum::<u64>()
        };
        let ours = OURS.to_string();
        let mut items = vec![
            count(
                "stability-ours-wrong".into(),
                format!("rays ours answered wrongly in {} cases", cases.len()),
                of(&ours, |c, i| {
                    let b = &c.verdicts.backends[i];
                    Some(b.faults() + b.nan_outputs)
                }),
                "stability",
            ),
            count(
                "stability-panics".into(),
                "cases that panicked or failed".into(),
                cases.iter().map(|c| c.panics).sum(),
                "stability",
            ),
        ];
        for name in BackendName::defaults().iter().map(|b| b.to_string()) {
            items.push(count(
                format!("stability-leaks-{name}"),
                format!("leaks of {name}: misses of rays that had to hit and exactly do"),
                of(&name, |c, i| c.leaks(i)),
                "stability",
            ));
        }
        let form = if data.stability_quick {
            "quick"
        } else {
            "full"
        };
        self.groups
            .push((format!("Numerical stability ({form} catalogue)"), items));
    }

    fn tracers(&mut self, data: &ReportData) {
        let items = super::third_party()
            .iter()
            .map(|name| {
                let name = name.to_string();
                let scenes: u64 = data
                    .tracers
                    .iter()
                    .filter_map(|t| t.verdicts.backend(&name))
                    .map(|b| b.wrong)
                    .sum();
                count(
                    format!("tracer-wrong-{name}"),
                    format!(
                        "rays {name} answered wrongly on {} scenes",
                        data.tracers.len()
                    ),
                    scenes,
                    "tracers",
                )
            })
            .collect();
        self.groups.push(("Third-party tracers".into(), items));
    }

    pub fn html(&self) -> String {
        let mut out = String::from("<div class=\"summary\">\n");
        for (title, items) in &self.groups {
            out += &format!("<h3>{}</h3><div class=\"items\">", escape_html(title));
            for item in items {
                let class = match item.tone {
                    Tone::Good => "good",
                    Tone::Bad => "bad",
                    Tone::Warn => "warn",
                    Tone::Plain | Tone::NotApplicable => "plain",
                };
                out += &format!(
                    "<a class=\"item {class}\" href=\"#{}\"><span class=\"value\" data-summary=\"{}\">{}</span>\
                     <span class=\"label\">{}</span></a>",
                    item.section,
                    escape_html(&item.key),
                    escape_html(&item.value),
                    escape_html(&item.label)
                );
            }
            out += "</div>\n";
        }
        out + "</div>\n"
    }

    pub fn markdown(&self) -> String {
        let mut out = String::from("## Summary\n\n");
        for (title, items) in &self.groups {
            out += &format!("**{title}**\n\n");
            for item in items {
                out += &format!("- {}: **{}**\n", item.label, item.value);
            }
            out += "\n";
        }
        out
    }
}
