//! The page checks of the browser test: open a page from disk in Chromium
//! and list what a reader would find broken. Every request outside the
//! page's folder is blocked (through the DevTools Fetch domain) and
//! reported, so the test never reaches the network.

use super::chromium::Chromium;
use chromiumoxide::Page;
use chromiumoxide::cdp::IntoEventKind;
use chromiumoxide::cdp::browser_protocol::fetch::{
    ContinueRequestParams, EnableParams, EventRequestPaused, FailRequestParams, RequestPattern,
};
use chromiumoxide::cdp::browser_protocol::log::{EventEntryAdded, LogEntryLevel};
use chromiumoxide::cdp::browser_protocol::network::{ErrorReason, EventRequestWillBeSent};
use chromiumoxide::cdp::browser_protocol::page::CaptureScreenshotFormat;
use chromiumoxide::cdp::js_protocol::runtime::{
    ConsoleApiCalledType, EvaluateParams, EventConsoleApiCalled, EventExceptionThrown, RemoteObject,
};
use chromiumoxide::listeners::EventStream;
use chromiumoxide::page::ScreenshotParams;
use futures::{FutureExt, StreamExt};
use serde::Deserialize;
use std::fmt;
use std::path::Path;
use std::sync::Arc;
use tokio::task::JoinHandle;

/// One thing wrong with a page.
#[derive(Debug)]
pub enum Finding {
    /// An `<img>` whose natural width or height is 0: it did not load.
    ImageNotLoaded { src: String },
    /// An `<svg>`, inline or as an `<img>`, laid out with no area.
    EmptySvg { element: String },
    /// A console message at level error: `console.error`, or the browser's
    /// own (a resource that failed to load, a refused style sheet, ...).
    ConsoleError { text: String },
    /// An exception that no script caught.
    UncaughtException { text: String },
    /// A request for anything but a file in the page's folder (`data:` URIs
    /// are part of the page and allowed).
    RequestLeftFolder { url: String },
    /// The page is wider than the window, or elements pass its right edge
    /// outside a box that scrolls by itself (`overflowing`, outermost first).
    HorizontalOverflow {
        page_width: f64,
        window_width: f64,
        overflowing: Vec<String>,
    },
}

impl fmt::Display for Finding {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            Finding::ImageNotLoaded { src } => write!(f, "image did not load: {src}"),
            Finding::EmptySvg { element } => write!(f, "SVG with no area: {element}"),
            Finding::ConsoleError { text } => write!(f, "console error: {text}"),
            Finding::UncaughtException { text } => write!(f, "uncaught exception: {text}"),
            Finding::RequestLeftFolder { url } => write!(f, "request outside the folder: {url}"),
            Finding::HorizontalOverflow {
                page_width,
                window_width,
                overflowing,
            } => write!(
                f,
                "page {page_width} px wide in a {window_width}-px window; overflowing: {}",
                overflowing.join("; ")
            ),
        }
    }
}

/// What `layout.js` measures in the loaded page.
#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct Layout {
    window_width: f64,
    page_width: f64,
    images_not_loaded: Vec<String>,
    empty_svgs: Vec<String>,
    overflowing: Vec<String>,
}

/// `path` as a `file://` URL, each byte outside the unreserved set and `/`
/// percent-encoded (RFC 3986, section 2).
fn file_url(path: &Path) -> String {
    let mut url = String::from("file://");
    for &byte in path.as_os_str().as_encoded_bytes() {
        if byte.is_ascii_alphanumeric() || b"-._~/".contains(&byte) {
            url.push(byte as char);
        } else {
            url.push_str(&format!("%{byte:02X}"));
        }
    }
    url
}

/// The events `stream` holds now. The handler hands events over in the
/// order Chromium sent them, so once a command's answer is in, every event
/// sent before it is here.
fn drain<T: IntoEventKind + Unpin>(stream: &mut EventStream<T>) -> Vec<Arc<T>> {
    std::iter::from_fn(|| stream.next().now_or_never().flatten()).collect()
}

/// What the browser saw while the page loaded.
struct Observed {
    layout: Layout,
    /// Every URL requested, in order.
    requests: Vec<String>,
    uncaught_exceptions: Vec<String>,
    /// `console.error` calls, as printed.
    console_errors: Vec<String>,
    /// The browser's own error messages, with the URL each is about.
    browser_errors: Vec<(String, Option<String>)>,
}

/// Opens `page` (an HTML file) from disk in a 1400-px-wide window and returns
/// what is wrong with it. With `screenshot`, also writes a full-page PNG
/// there.
pub fn check_page(chromium: &Chromium, page: &Path, screenshot: Option<&Path>) -> Vec<Finding> {
    let page = page.canonicalize().unwrap();
    let folder = file_url(page.parent().unwrap()) + "/";
    let allowed = move |url: &str| url.starts_with(&folder) || url.starts_with("data:");
    let observed = chromium
        .runtime
        .block_on(observe(chromium, &page, allowed.clone(), screenshot));
    findings(observed, allowed)
}

/// Loads `page` with every request outside `allowed` blocked, measures it
/// with `layout.js` and gathers the events it caused.
async fn observe(
    chromium: &Chromium,
    page: &Path,
    allowed: impl Fn(&str) -> bool + Send + 'static,
    screenshot: Option<&Path>,
) -> Observed {
    let tab = chromium.browser.new_page("about:blank").await.unwrap();
    let mut requests = tab
        .event_listener::<EventRequestWillBeSent>()
        .await
        .unwrap();
    let mut exceptions = tab.event_listener::<EventExceptionThrown>().await.unwrap();
    let mut console_calls = tab.event_listener::<EventConsoleApiCalled>().await.unwrap();
    let mut browser_log = tab.event_listener::<EventEntryAdded>().await.unwrap();
    let blocker = block_outside_requests(&tab, allowed).await;

    tab.goto(file_url(page)).await.unwrap();
    let layout: Layout = tab
        .evaluate_expression(
            EvaluateParams::builder()
                .expression(include_str!("layout.js"))
                .await_promise(true)
                .return_by_value(true)
                .build()
                .unwrap(),
        )
        .await
        .unwrap()
        .into_value()
        .unwrap();
    if let Some(path) = screenshot {
        let png = ScreenshotParams::builder()
            .format(CaptureScreenshotFormat::Png)
            .full_page(true)
            .build();
        tab.save_screenshot(png, path).await.unwrap();
    }
    tab.close().await.unwrap();
    blocker.abort();

    Observed {
        layout,
        requests: drain(&mut requests)
            .iter()
            .map(|event| event.request.url.clone())
            .collect(),
        uncaught_exceptions: drain(&mut exceptions)
            .iter()
            .map(|event| {
                let details = &event.exception_details;
                let thrown = details.exception.as_ref();
                thrown
                    .and_then(|exception| exception.description.clone())
                    .unwrap_or_else(|| details.text.clone())
            })
            .collect(),
        console_errors: drain(&mut console_calls)
            .iter()
            .filter(|call| call.r#type == ConsoleApiCalledType::Error)
            .map(|call| console_text(&call.args))
            .collect(),
        browser_errors: drain(&mut browser_log)
            .iter()
            .filter(|event| event.entry.level == LogEntryLevel::Error)
            .map(|event| (event.entry.text.clone(), event.entry.url.clone()))
            .collect(),
    }
}

/// What is wrong with an observed page, in the order: requests outside the
/// folder, images, SVGs, overflow, exceptions, console errors. A browser
/// error about a URL that an earlier finding names (the failed load of a
/// missing image, a blocked request) is not repeated.
fn findings(observed: Observed, allowed: impl Fn(&str) -> bool) -> Vec<Finding> {
    let Observed {
        layout,
        mut requests,
        uncaught_exceptions,
        console_errors,
        browser_errors,
    } = observed;
    requests.retain(|url| !allowed(url));
    requests.sort();
    requests.dedup();
    let mut findings: Vec<Finding> = requests
        .into_iter()
        .map(|url| Finding::RequestLeftFolder { url })
        .collect();
    findings.extend(
        layout
            .images_not_loaded
            .into_iter()
            .map(|src| Finding::ImageNotLoaded { src }),
    );
    findings.extend(
        layout
            .empty_svgs
            .into_iter()
            .map(|element| Finding::EmptySvg { element }),
    );
    if layout.page_width > layout.window_width || !layout.overflowing.is_empty() {
        findings.push(Finding::HorizontalOverflow {
            page_width: layout.page_width,
            window_width: layout.window_width,
            overflowing: layout.overflowing,
        });
    }
    let named: Vec<String> = findings.iter().filter_map(named_url).collect();
    findings.extend(
        uncaught_exceptions
            .into_iter()
            .map(|text| Finding::UncaughtException { text }),
    );
    let unexplained_browser_errors = browser_errors
        .into_iter()
        .filter(|(_, url)| url.as_ref().is_none_or(|url| !named.contains(url)))
        .map(|(text, _)| text);
    findings.extend(
        console_errors
            .into_iter()
            .chain(unexplained_browser_errors)
            .map(|text| Finding::ConsoleError { text }),
    );
    findings
}

/// A console call's arguments as the console prints them, space-separated.
fn console_text(args: &[RemoteObject]) -> String {
    let words: Vec<String> = args
        .iter()
        .map(|arg| match &arg.value {
            Some(serde_json::Value::String(text)) => text.clone(),
            Some(value) => value.to_string(),
            None => arg.description.clone().unwrap_or_default(),
        })
        .collect();
    words.join(" ")
}

/// The URL a finding is about, if it is about one.
fn named_url(finding: &Finding) -> Option<String> {
    match finding {
        Finding::ImageNotLoaded { src: url } | Finding::RequestLeftFolder { url } => {
            Some(url.clone())
        }
        _ => None,
    }
}

/// Pauses every request of `tab` (Fetch domain): lets the allowed ones
/// through and fails the others as blocked, so none reaches the network.
async fn block_outside_requests(
    tab: &Page,
    allowed: impl Fn(&str) -> bool + Send + 'static,
) -> JoinHandle<()> {
    let mut paused = tab.event_listener::<EventRequestPaused>().await.unwrap();
    let answerer = tab.clone();
    let answering = tokio::spawn(async move {
        while let Some(request) = paused.next().await {
            let id = request.request_id.clone();
            // A request the page gave up on while paused cannot be answered.
            let _ = if allowed(&request.request.url) {
                answerer
                    .execute(ContinueRequestParams::new(id))
                    .await
                    .map(drop)
            } else {
                answerer
                    .execute(FailRequestParams::new(id, ErrorReason::BlockedByClient))
                    .await
                    .map(drop)
            };
        }
    });
    let every_url = RequestPattern::builder().url_pattern("*").build();
    tab.execute(EnableParams::builder().pattern(every_url).build())
        .await
        .unwrap();
    answering
}
