//! Figures as SVG: line and scatter plots on linear or log10 axes, with a
//! legend and the run's stamp (machine, date, commit, threads) beneath.
//!
//! SVG keeps the figures exact, small and readable in any browser next to
//! the report's tables; nothing here depends on fonts being installed.

use crate::results::table::escape_html;
use std::fmt::Write as _;

/// How an axis maps values to positions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    Linear,
    /// Base-10 logarithmic; non-positive values are left out.
    Log10,
    /// Whole numbers counting things (saved runs, say): linear, ticks only
    /// at whole numbers, half a step of room either side.
    Count,
}

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mark {
    Line,
    Points,
    LineAndPoints,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    pub mark: Mark,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Plot {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x_scale: Scale,
    pub y_scale: Scale,
    pub series: Vec<Series>,
    /// The stamp under the figure: where and when its numbers were measured.
    pub caption: String,
}

/// Width of the plotting area; the legend beside it is as wide as its
/// longest entry needs.
const PLOT_WIDTH: f64 = 400.0;
const HEIGHT: f64 = 420.0;
const LEFT: f64 = 70.0;
/// Room the legend takes per character of an entry, at the 12 px font.
const LEGEND_CHAR_WIDTH: f64 = 7.0;
/// Room the caption takes per character, at its 10 px font: the image is
/// widened to hold it, which would otherwise be cut at the right edge.
const CAPTION_CHAR_WIDTH: f64 = 5.5;
const TOP: f64 = 36.0;
const BOTTOM: f64 = 74.0;
/// Colour-blind-safe series colours (Okabe & Ito 2008).
const COLOURS: [&str; 8] = [
    "#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#F0E442", "#000000",
];

impl Scale {
    fn map(self, v: f64) -> Option<f64> {
        match self {
            Scale::Linear | Scale::Count => v.is_finite().then_some(v),
            Scale::Log10 => (v > 0.0 && v.is_finite()).then(|| v.log10()),
        }
    }

    /// Tick positions (in mapped units) and their labels for `[lo, hi]`.
    fn ticks(self, lo: f64, hi: f64) -> Vec<(f64, String)> {
        match self {
            Scale::Log10 => (lo.floor() as i32..=hi.ceil() as i32)
                .map(|e| (e as f64, format!("1e{e}")))
                .collect(),
            Scale::Linear => {
                let step = nice_step((hi - lo) / 5.0);
                let first = (lo / step).floor() as i64;
                let last = (hi / step).ceil() as i64;
                (first..=last)
                    .map(|i| {
                        let v = i as f64 * step;
                        (v, format!("{}", (v * 1e6).round() / 1e6))
                    })
                    .collect()
            }
            Scale::Count => {
                let step = nice_step((hi - lo) / 5.0).max(1.0);
                let first = (lo / step).ceil() as i64;
                let last = (hi / step).floor() as i64;
                (first..=last)
                    .map(|i| {
                        let v = i as f64 * step;
                        (v, format!("{v}"))
                    })
                    .collect()
            }
        }
    }
}

/// 1, 2 or 5 times a power of ten, at least `raw`.
fn nice_step(raw: f64) -> f64 {
    if !(raw > 0.0 && raw.is_finite()) {
        return 1.0;
    }
    let power = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * power)
        .find(|&s| s >= raw)
        .unwrap_or(10.0 * power)
}

/// The range of mapped values, widened when empty or a single value.
fn extent(values: impl Iterator<Item = f64>, scale: Scale) -> (f64, f64) {
    let (lo, hi) = values
        .filter_map(|v| scale.map(v))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        (0.0, 1.0)
    } else if lo == hi && lo == 0.0 {
        // All zero (a rate that never happened): keep the axis non-negative.
        (0.0, 1.0)
    } else if lo == hi || scale == Scale::Count {
        (lo - 0.5, hi + 0.5)
    } else {
        match scale {
            Scale::Log10 => (lo.floor(), hi.ceil()),
            Scale::Linear | Scale::Count => (lo, hi),
        }
    }
}

impl Plot {
    /// The figure as a standalone SVG document.
    pub fn to_svg(&self) -> String {
        let points = || self.series.iter().flat_map(|s| s.points.iter());
        let (x0, x1) = extent(points().map(|p| p.0), self.x_scale);
        let (y0, y1) = extent(points().map(|p| p.1), self.y_scale);
        let x_ticks = self.x_scale.ticks(x0, x1);
        let y_ticks = self.y_scale.ticks(y0, y1);
        // Ticks of a linear axis may reach past the data: span them all.
        let (x0, x1) = span(&x_ticks, x0, x1);
        let (y0, y1) = span(&y_ticks, y0, y1);
        let plot_w = PLOT_WIDTH;
        let longest = self.series.iter().map(|s| s.name.chars().count()).max();
        let width = (LEFT + plot_w + 40.0 + LEGEND_CHAR_WIDTH * longest.unwrap_or(0) as f64)
            .max(16.0 + CAPTION_CHAR_WIDTH * self.caption.chars().count() as f64);
        let plot_h = HEIGHT - TOP - BOTTOM;
        let px = |x: f64| LEFT + (x - x0) / (x1 - x0) * plot_w;
        let py = |y: f64| TOP + plot_h - (y - y0) / (y1 - y0) * plot_h;

        let mut svg = format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{HEIGHT}\" \
             viewBox=\"0 0 {width} {HEIGHT}\" font-family=\"sans-serif\" font-size=\"12\">\n\
             <rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n\
             <text x=\"{}\" y=\"20\" text-anchor=\"middle\" font-size=\"14\">{}</text>\n",
            LEFT + plot_w / 2.0,
            escape_html(&self.title)
        );
        for (v, label) in &x_ticks {
            let x = px(*v);
            let _ = writeln!(
                svg,
                "<line x1=\"{x:.1}\" y1=\"{TOP}\" x2=\"{x:.1}\" y2=\"{:.1}\" stroke=\"#ddd\"/>\
                 <text x=\"{x:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{}</text>",
                TOP + plot_h,
                TOP + plot_h + 16.0,
                escape_html(label)
            );
        }
        for (v, label) in &y_ticks {
            let y = py(*v);
            let _ = writeln!(
                svg,
                "<line x1=\"{LEFT}\" y1=\"{y:.1}\" x2=\"{:.1}\" y2=\"{y:.1}\" stroke=\"#ddd\"/>\
                 <text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\">{}</text>",
                LEFT + plot_w,
                LEFT - 6.0,
                y + 4.0,
                escape_html(label)
            );
        }
        let _ = writeln!(
            svg,
            "<rect x=\"{LEFT}\" y=\"{TOP}\" width=\"{plot_w}\" height=\"{plot_h}\" fill=\"none\" stroke=\"#444\"/>\n\
             <text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{}</text>\n\
             <text transform=\"translate(16 {:.1}) rotate(-90)\" text-anchor=\"middle\">{}</text>",
            LEFT + plot_w / 2.0,
            TOP + plot_h + 34.0,
            escape_html(&self.x_label),
            TOP + plot_h / 2.0,
            escape_html(&self.y_label)
        );
        for (i, series) in self.series.iter().enumerate() {
            let colour = COLOURS[i % COLOURS.len()];
            let mapped: Vec<(f64, f64)> = series
                .points
                .iter()
                .filter_map(|&(x, y)| Some((px(self.x_scale.map(x)?), py(self.y_scale.map(y)?))))
                .collect();
            if series.mark != Mark::Points && mapped.len() > 1 {
                let path: Vec<String> = mapped
                    .iter()
                    .map(|(x, y)| format!("{x:.1},{y:.1}"))
                    .collect();
                let _ = writeln!(
                    svg,
                    "<polyline points=\"{}\" fill=\"none\" stroke=\"{colour}\" stroke-width=\"1.5\"/>",
                    path.join(" ")
                );
            }
            if series.mark != Mark::Line {
                for (x, y) in &mapped {
                    let _ = writeln!(
                        svg,
                        "<circle cx=\"{x:.1}\" cy=\"{y:.1}\" r=\"3\" fill=\"{colour}\"/>"
                    );
                }
            }
            let ly = TOP + 10.0 + 18.0 * i as f64;
            let lx = LEFT + plot_w + 12.0;
            let _ = writeln!(
                svg,
                "<rect x=\"{lx}\" y=\"{:.1}\" width=\"12\" height=\"4\" fill=\"{colour}\"/>\
                 <text x=\"{:.1}\" y=\"{:.1}\">{}</text>",
                ly - 4.0,
                lx + 16.0,
                ly + 1.0,
                escape_html(&series.name)
            );
        }
        let _ = writeln!(
            svg,
            "<text x=\"8\" y=\"{:.1}\" font-size=\"10\" fill=\"#666\">{}</text>\n</svg>",
            HEIGHT - 10.0,
            escape_html(&self.caption)
        );
        svg
    }

    pub fn save(&self, path: &std::path::Path) -> anyhow::Result<()> {
        std::fs::write(path, self.to_svg())
            .map_err(|e| anyhow::anyhow!("writing {}: {e}", path.display()))
    }
}

fn span(ticks: &[(f64, String)], lo: f64, hi: f64) -> (f64, f64) {
    let first = ticks.first().map_or(lo, |t| t.0.min(lo));
    let last = ticks.last().map_or(hi, |t| t.0.max(hi));
    if last > first {
        (first, last)
    } else {
        (first, first + 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plot(scale: Scale) -> Plot {
        Plot {
            title: "t <1>".into(),
            x_label: "triangles".into(),
            y_label: "ms".into(),
            x_scale: scale,
            y_scale: scale,
            series: vec![Series {
                name: "ours".into(),
                points: vec![(10.0, 1.0), (1000.0, 100.0), (-1.0, 5.0)],
                mark: Mark::LineAndPoints,
            }],
            caption: "machine · date".into(),
        }
    }

    #[test]
    fn log_axes_leave_out_non_positive_values_and_tick_decades() {
        let svg = plot(Scale::Log10).to_svg();
        assert_eq!(svg.matches("<circle").count(), 2, "{svg}");
        for tick in ["1e1", "1e2", "1e3", "1e0"] {
            assert!(svg.contains(&format!(">{tick}<")), "{tick} missing: {svg}");
        }
        assert!(svg.contains("t &lt;1&gt;"));
        assert!(svg.contains("machine · date"));
    }

    #[test]
    fn the_image_is_wide_enough_for_its_caption() {
        let width = |plot: &Plot| -> f64 {
            let svg = plot.to_svg();
            let start = svg.find("width=\"").unwrap() + 7;
            svg[start..].split('"').next().unwrap().parse().unwrap()
        };
        let short = plot(Scale::Linear);
        let mut long = plot(Scale::Linear);
        long.caption = "machine · date · ".repeat(12);
        assert!(width(&long) > width(&short));
        assert!(width(&long) >= CAPTION_CHAR_WIDTH * long.caption.chars().count() as f64);
    }

    #[test]
    fn linear_axes_keep_every_finite_point() {
        let svg = plot(Scale::Linear).to_svg();
        assert_eq!(svg.matches("<circle").count(), 3, "{svg}");
    }

    #[test]
    fn a_count_axis_ticks_whole_numbers_only() {
        assert_eq!(Scale::Count.ticks(0.5, 1.5), [(1.0, "1".to_string())]);
        let ticks: Vec<f64> = Scale::Count.ticks(0.5, 3.5).iter().map(|t| t.0).collect();
        assert_eq!(ticks, [1.0, 2.0, 3.0]);
        let ticks: Vec<f64> = Scale::Count.ticks(0.5, 40.5).iter().map(|t| t.0).collect();
        assert_eq!(ticks, [10.0, 20.0, 30.0, 40.0]);
        assert_eq!(extent([1.0, 1.0].into_iter(), Scale::Count), (0.5, 1.5));
        assert_eq!(extent([1.0, 3.0].into_iter(), Scale::Count), (0.5, 3.5));
    }

    #[test]
    fn nice_steps() {
        assert_eq!(nice_step(0.3), 0.5);
        assert_eq!(nice_step(7.0), 10.0);
        assert_eq!(nice_step(1.0), 1.0);
        assert_eq!(nice_step(120.0), 200.0);
    }
}
