//! The report in a real browser: a quick report opened from disk in headless
//! Chromium passes every page check, and each check is shown to catch the
//! fault planted in a small fixture page (`tests/data/browser/`).

mod check;
mod chromium;

use check::{Finding, check_page};
use chromium::{Chromium, WINDOW_WIDTH};
use std::path::{Path, PathBuf};

/// Where the full-page screenshot of the quick report goes, for a person to
/// look at: `target/report-screenshot.png`.
fn screenshot_path() -> PathBuf {
    let target = Path::new(env!("CARGO_TARGET_TMPDIR")).parent().unwrap();
    target.join("report-screenshot.png")
}

#[test]
fn quick_report_passes_every_page_check() {
    let index = crate::support::quick_report().join("index.html");
    let chromium = Chromium::launch();
    let screenshot = screenshot_path();
    let findings = check_page(&chromium, &index, Some(&screenshot));
    let listed: Vec<String> = findings.iter().map(Finding::to_string).collect();
    assert!(
        findings.is_empty(),
        "the quick report has {} finding(s) (screenshot: {}):\n{}",
        findings.len(),
        screenshot.display(),
        listed.join("\n")
    );
    assert!(std::fs::metadata(&screenshot).unwrap().len() > 0);
}

/// Whether a fixture's findings are exactly the one fault it plants.
type Expected = fn(&[Finding]) -> bool;

/// Each fixture page with what it must yield (nothing, for `clean.html`).
const FIXTURES: [(&str, Expected); 7] = [
    ("clean.html", |found| found.is_empty()),
    (
        "broken-image.html",
        |found| matches!(found, [Finding::ImageNotLoaded { src }] if src.ends_with("/missing.png")),
    ),
    (
        "empty-svg.html",
        |found| matches!(found, [Finding::EmptySvg { element }] if element.starts_with("<svg#flat>")),
    ),
    (
        "external-url.html",
        |found| matches!(found, [Finding::RequestLeftFolder { url }] if url == "https://example.com/style.css"),
    ),
    (
        "console-error.html",
        |found| matches!(found, [Finding::ConsoleError { text }] if text == "planted error 42"),
    ),
    (
        "uncaught-exception.html",
        |found| matches!(found, [Finding::UncaughtException { text }] if text.contains("planted exception")),
    ),
    ("wide-table.html", |found| {
        matches!(found, [Finding::HorizontalOverflow { page_width, window_width, overflowing }]
            if *window_width == f64::from(WINDOW_WIDTH) && page_width > window_width && overflowing.len() == 1 && overflowing[0].starts_with("<table#wide>"))
    }),
];

#[test]
fn each_fixture_page_yields_exactly_the_finding_it_plants() {
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/browser");
    let chromium = Chromium::launch();
    let mismatches: Vec<String> = FIXTURES
        .iter()
        .filter_map(|(name, expected)| {
            let findings = check_page(&chromium, &fixtures.join(name), None);
            (!expected(&findings)).then(|| format!("{name}: {findings:#?}"))
        })
        .collect();
    assert!(mismatches.is_empty(), "{}", mismatches.join("\n"));
}
