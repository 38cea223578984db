//! Headless Chromium for the browser tests, driven over the DevTools
//! protocol with `chromiumoxide`: found through `CHROMIUM` or `chromium` on
//! `PATH`, started offline in a fresh profile with a 1400-px-wide window.

use chromiumoxide::handler::viewport::Viewport;
use chromiumoxide::{Browser, BrowserConfig};
use futures::StreamExt;
use std::path::PathBuf;
use tempfile::TempDir;
use tokio::runtime::Runtime;
use tokio::task::JoinHandle;

/// The window's width in CSS pixels: the page must fit it without sideways scrolling.
pub const WINDOW_WIDTH: u32 = 1400;
const WINDOW_HEIGHT: u32 = 1000;

/// Flags that keep Chromium off the network: no background fetches, no
/// component or sync traffic, no QUIC probing, no first-run set-up.
const OFFLINE_FLAGS: [&str; 6] = [
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
];

/// How to get a browser when none is found.
const INSTALL_HINT: &str = "the browser test needs Chromium: run `scripts/test` \
    (as root on Debian it installs the `chromium` package), install it yourself \
    (`apt-get install chromium` on Debian), or set CHROMIUM to the path of a \
    Chromium or Chrome executable";

/// The browser: `$CHROMIUM` if set, else `chromium` on `PATH`. Panics with
/// [`INSTALL_HINT`] when there is none, so a missing browser fails the test
/// instead of skipping it.
fn executable() -> PathBuf {
    if let Some(path) = std::env::var_os("CHROMIUM") {
        let path = PathBuf::from(path);
        assert!(
            path.is_file(),
            "CHROMIUM={} is not a file; {INSTALL_HINT}",
            path.display()
        );
        return path;
    }
    std::env::var_os("PATH")
        .iter()
        .flat_map(std::env::split_paths)
        .map(|dir| dir.join("chromium"))
        .find(|candidate| candidate.is_file())
        .unwrap_or_else(|| panic!("no `chromium` on PATH and CHROMIUM is not set; {INSTALL_HINT}"))
}

/// A running headless Chromium and the runtime that drives it.
pub struct Chromium {
    pub runtime: Runtime,
    pub browser: Browser,
    handler: JoinHandle<()>,
    _profile: TempDir,
}

impl Chromium {
    pub fn launch() -> Chromium {
        let executable = executable();
        let profile = tempfile::tempdir().unwrap();
        let config = BrowserConfig::builder()
            .chrome_executable(&executable)
            .no_sandbox()
            .user_data_dir(profile.path())
            .window_size(WINDOW_WIDTH, WINDOW_HEIGHT)
            .viewport(Viewport {
                width: WINDOW_WIDTH,
                height: WINDOW_HEIGHT,
                device_scale_factor: Some(1.0),
                ..Viewport::default()
            })
            .args(OFFLINE_FLAGS)
            .build()
            .unwrap();
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(2)
            .enable_all()
            .build()
            .unwrap();
        let (browser, mut handler) = runtime
            .block_on(Browser::launch(config))
            .unwrap_or_else(|error| panic!("{} did not start: {error}", executable.display()));
        // The handler carries every protocol message; it must be polled for
        // the whole session. Events this crate version cannot parse come out
        // as errors and are passed over.
        let handler = runtime.spawn(async move { while handler.next().await.is_some() {} });
        Chromium {
            runtime,
            browser,
            handler,
            _profile: profile,
        }
    }
}

impl Drop for Chromium {
    fn drop(&mut self) {
        self.runtime.block_on(async {
            // A browser that already died has nothing left to close.
            if self.browser.close().await.is_ok() {
                let _ = self.browser.wait().await;
            }
        });
        self.handler.abort();
    }
}
