//! Captures what native code prints to standard output (file descriptor 1)
//! while a closure runs, by pointing descriptor 1 at a temporary file
//! (`dup`/`dup2`) and flushing C stdio (`fflush(NULL)`) before restoring it.

use std::fs::File;
use std::io::{self, Read, Seek, SeekFrom, Write};
use std::os::fd::AsRawFd;
use std::sync::Mutex;

/// Descriptor 1 is process-wide: one capture at a time.
static CAPTURE_LOCK: Mutex<()> = Mutex::new(());

/// Runs `body` with standard output redirected; returns its result and the
/// text written meanwhile (by any thread of the process).
pub(crate) fn capture_stdout<T>(body: impl FnOnce() -> T) -> io::Result<(T, String)> {
    let _only_capture = CAPTURE_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let mut sink: File = tempfile::tempfile()?;
    io::stdout().flush()?;
    let redirect = Redirect::new(sink.as_raw_fd())?;
    let result = body();
    redirect.restore()?;
    let mut text = String::new();
    sink.seek(SeekFrom::Start(0))?;
    sink.read_to_string(&mut text)?;
    Ok((result, text))
}

/// Descriptor 1 pointed elsewhere; the original is put back on `restore`
/// or, if that is never reached, on drop.
struct Redirect {
    saved_stdout: libc::c_int,
}

impl Redirect {
    fn new(target: libc::c_int) -> io::Result<Self> {
        // SAFETY: duplicating descriptor 1, which every process has.
        let saved_stdout = unsafe { libc::dup(libc::STDOUT_FILENO) };
        if saved_stdout < 0 {
            return Err(io::Error::last_os_error());
        }
        let redirect = Redirect { saved_stdout };
        // SAFETY: `target` is an open descriptor owned by the caller.
        if unsafe { libc::dup2(target, libc::STDOUT_FILENO) } < 0 {
            return Err(io::Error::last_os_error());
        }
        Ok(redirect)
    }

    fn restore(self) -> io::Result<()> {
        let result = self.put_back();
        std::mem::forget(self);
        result
    }

    fn put_back(&self) -> io::Result<()> {
        let rust_flush = io::stdout().flush();
        // SAFETY: flushing every C stdio stream, then moving the saved
        // descriptor back onto 1 and closing the copy we own.
        unsafe {
            libc::fflush(std::ptr::null_mut());
            let restored = libc::dup2(self.saved_stdout, libc::STDOUT_FILENO);
            libc::close(self.saved_stdout);
            if restored < 0 {
                return Err(io::Error::last_os_error());
            }
        }
        rust_flush
    }
}

impl Drop for Redirect {
    fn drop(&mut self) {
        // Only reached on an early error; nothing more can be reported.
        let _ = self.put_back();
    }
}
