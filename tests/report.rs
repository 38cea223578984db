//! The quick report: its sections, tables, images and stamps, and a
//! summary that says what the sections below it say.

use crate::support::quick_report;
use serde_json::Value;

#[test]
fn quick_report_writes_tables_and_images() {
    let dir = quick_report();
    let markdown = std::fs::read_to_string(dir.join("report.md")).unwrap();
    for needle in [
        "## Summary",
        "## Contents",
        "## Agreement with Embree",
        "## Third-party tracers",
        "## Feature gallery",
        "## Performance",
        "## Numerical stability",
        "## Error against run time",
        "cornell",
        "monkey",
        "dragon-11k",
        "obvhs",
        "parry3d",
        "build ms",
        "commit",
        "render ms, Embree",
        "Speed relative to embree",
        "primary Mrays/s",
        "images/cornell-difference.png",
        "images/scaling-build-",
        "images/scaling-ray-",
        "closed_mesh_leaks",
        "images/stability-epsilon.svg",
        "images/stability-gap.svg",
        "smallest gap resolved",
        "The quick form",
    ] {
        assert!(markdown.contains(needle), "report.md lacks {needle}");
    }
    for file in [
        "index.html",
        "report.json",
        "tables.json",
        "tables/agreement-1.csv",
        "tables/stability-1.csv",
        "images/cornell.png",
        "images/cornell.exr",
        "images/cornell-difference.png",
        "images/gallery-cornell-bloom-bloom-mask.png",
        "images/gallery-monkey-smooth-normals.png",
    ] {
        assert!(dir.join(file).is_file(), "{file} missing");
    }
    // Every table of the page is in tables.json, with its CSV.
    let tables: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("tables.json")).unwrap()).unwrap();
    let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
    let entries = tables.as_array().unwrap();
    assert_eq!(entries.len(), html.matches("<table>").count());
    for entry in entries {
        let csv = std::fs::read_to_string(dir.join(entry["csv"].as_str().unwrap())).unwrap();
        assert_eq!(
            csv.lines().count(),
            entry["rows"].as_array().unwrap().len() + 1
        );
    }
    // Every image carries the run's stamp.
    let png = std::fs::File::open(dir.join("images/cornell.png")).unwrap();
    let reader = png::Decoder::new(std::io::BufReader::new(png))
        .read_info()
        .unwrap();
    let stamp: Vec<String> = reader
        .info()
        .utf8_text
        .iter()
        .map(|t| t.get_text().unwrap())
        .collect();
    let commit = markdown
        .split("commit ")
        .nth(1)
        .and_then(|s| s.split_whitespace().next())
        .unwrap();
    assert!(
        stamp
            .iter()
            .any(|t| t.contains(&format!("commit {commit}"))),
        "{stamp:?}"
    );
    let plots: Vec<String> = std::fs::read_dir(dir.join("images"))
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|name| name.starts_with("scaling-") && name.ends_with(".svg"))
        .collect();
    let count = |prefix: &str| plots.iter().filter(|n| n.starts_with(prefix)).count();
    assert!(count("scaling-build-") >= 1, "{plots:?}");
    assert_eq!(
        count("scaling-build-"),
        count("scaling-ray-"),
        "a build and a ray plot per thread count: {plots:?}"
    );
    assert_eq!(count("scaling-bytes"), 1, "{plots:?}");
    assert_eq!(count("scaling-peak"), 1, "{plots:?}");
    assert_eq!(plots.len(), 2 * count("scaling-build-") + 2, "{plots:?}");
}

/// Each scene's render split names the load it was measured under, in
/// its JSON and in its table, where the system tells.
#[test]
fn the_render_split_names_its_load() {
    let dir = quick_report();
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap();
    let scenes = report["scenes"].as_array().unwrap();
    assert!(!scenes.is_empty());
    let proc_tells = std::path::Path::new("/proc/loadavg").is_file();
    for scene in scenes {
        let load = &scene["split_load_average"];
        assert_eq!(load.is_array(), proc_tells, "{}: {load}", scene["scene"]);
        for value in load.as_array().into_iter().flatten() {
            assert!(value.as_f64().is_some_and(|l| l >= 0.0), "{load}");
        }
    }
    let markdown = std::fs::read_to_string(dir.join("report.md")).unwrap();
    let header = markdown
        .lines()
        .find(|l| l.contains("render, ours / predicted by our tracing"))
        .expect("the split's table");
    assert!(
        header.ends_with("| load average (1 min) as the split ended |"),
        "{header}"
    );
}

/// The value the page's summary shows under `key`.
fn summary_value(html: &str, key: &str) -> String {
    let marker = format!("data-summary=\"{key}\">");
    let start = html
        .find(&marker)
        .unwrap_or_else(|| panic!("no summary item {key}"))
        + marker.len();
    let end = start + html[start..].find('<').unwrap();
    html[start..end].to_string()
}

/// Sums `field` of the backend named `name` over `verdicts` objects.
fn sum_of<'a>(verdicts: impl Iterator<Item = &'a Value>, name: &str, fields: &[&str]) -> u64 {
    verdicts
        .flat_map(|v| v["backends"].as_array().unwrap())
        .filter(|b| b["name"] == name)
        .map(|b| fields.iter().map(|f| b[*f].as_u64().unwrap()).sum::<u64>())
        .sum()
}

/// The summary's numbers, recomputed here from `report.json`, the data the
/// sections below it are drawn from.
#[test]
fn the_summary_agrees_with_the_sections() {
    let dir = quick_report();
    let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
    let data: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap();
    let scenes = data["scenes"].as_array().unwrap();
    let agreements = || scenes.iter().map(|s| &s["agreement"]["verdicts"]);
    let rays: u64 = agreements().map(|v| v["rays"].as_u64().unwrap()).sum();
    assert_eq!(summary_value(&html, "rays-checked"), rays.to_string());
    for name in ["ours", "ours-sah", "ours-median", "embree", "embree-robust"] {
        assert_eq!(
            summary_value(&html, &format!("wrong-{name}")),
            sum_of(agreements(), name, &["wrong", "t_off"]).to_string(),
            "{name}"
        );
    }
    let ours_to_blame: u64 = scenes
        .iter()
        .map(|s| {
            s["pixels"]["first_wrong"].as_u64().unwrap()
                + s["pixels"]["unexplained"].as_u64().unwrap()
        })
        .sum();
    assert_eq!(
        summary_value(&html, "pixels-ours-to-blame"),
        ours_to_blame.to_string()
    );
    let tracers = data["tracers"].as_array().unwrap();
    for name in ["obvhs", "bvh", "parry3d"] {
        assert_eq!(
            summary_value(&html, &format!("tracer-wrong-{name}")),
            sum_of(tracers.iter().map(|t| &t["verdicts"]), name, &["wrong"]).to_string(),
            "{name}"
        );
    }
    for scene in data["sweep"]["sampled"].as_array().unwrap() {
        for curve in scene["samplers"].as_array().unwrap() {
            let key = format!(
                "slope-{}-{}",
                scene["scene"].as_str().unwrap(),
                curve["sampler"].as_str().unwrap()
            );
            let slope = curve["fits"]["rel_mse_vs_samples"]["slope"]
                .as_f64()
                .unwrap();
            assert_eq!(
                summary_value(&html, &key),
                raycheck::report::summary::slope_text(slope)
            );
        }
    }
    let cases = data["stability"].as_array().unwrap();
    assert_eq!(
        summary_value(&html, "stability-ours-wrong"),
        sum_of(
            cases.iter().map(|c| &c["verdicts"]),
            "ours",
            &["wrong", "t_off", "nan_outputs"]
        )
        .to_string()
    );
    let panics: u64 = cases.iter().map(|c| c["panics"].as_u64().unwrap()).sum();
    assert_eq!(summary_value(&html, "stability-panics"), panics.to_string());
    // The speed ratios: ours over Embree on the largest benchmark scene
    // timed, at the most threads, from the medians.
    let rows = data["performance"]["rows"].as_array().unwrap();
    let largest = rows
        .iter()
        .filter(|r| !raycheck::scene::SCALE_SCENES.contains(&r["scene"].as_str().unwrap()))
        .max_by_key(|r| (r["triangles"].as_u64(), r["threads"].as_u64()))
        .unwrap();
    let row = |backend: &str| {
        rows.iter()
            .find(|r| {
                r["scene"] == largest["scene"]
                    && r["threads"] == largest["threads"]
                    && r["backend"] == backend
            })
            .unwrap()
    };
    let median = |r: &Value, metric: &str| r[metric]["median"].as_f64().unwrap();
    for baseline in ["embree", "embree-robust"] {
        let (ours, theirs) = (row("ours"), row(baseline));
        for (metric, key) in [
            ("mrays_primary", "primary"),
            ("mrays_shadow", "shadow"),
            ("mrays_diffuse", "diffuse"),
        ] {
            let ratio = median(ours, metric) / median(theirs, metric);
            assert_eq!(
                summary_value(&html, &format!("speed-{key}-{baseline}")),
                raycheck::report::summary::ratio_text(ratio),
                "{key} vs {baseline}"
            );
        }
        let build = median(theirs, "build_ms") / median(ours, "build_ms");
        assert_eq!(
            summary_value(&html, &format!("speed-build-{baseline}")),
            raycheck::report::summary::ratio_text(build)
        );
    }
}
