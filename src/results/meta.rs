//! What every number in the report is stamped with: the machine, the date,
//! the commit, the thread count and how busy the machine was.

use serde::{Deserialize, Serialize};
use std::process::Command;
use std::time::{SystemTime, UNIX_EPOCH};

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RunMeta {
    /// CPU model (its name, then family, model and stepping: cloud machines
    /// give one name to several generations), logical cores, memory and the
    /// Linux kernel's release, as read from `/proc`.
    pub machine: String,
    /// UTC, ISO 8601.
    pub date: String,
    /// `git describe`-style commit of the source tree, `+dirty` if modified.
    pub commit: String,
    pub threads: usize,
    /// `/proc/loadavg`'s 1, 5 and 15 minute load averages when the run
    /// began: near 0 on a quiet machine, near the core count on a busy one.
    #[serde(default)]
    pub load_average: Option<[f64; 3]>,
}

impl RunMeta {
    /// The stamp of a run beginning now, on `threads` worker threads.
    pub fn collect(threads: usize) -> Self {
        Self {
            machine: machine(),
            date: utc_now(),
            commit: commit(),
            threads,
            load_average: load_average(),
        }
    }

    /// The text chunks every report image carries: its title and this run.
    pub fn stamp(&self, title: &str) -> [(&'static str, String); 3] {
        [
            ("Title", title.to_string()),
            ("Comment", self.caption()),
            ("Software", "raycheck".to_string()),
        ]
    }

    /// One line for a caption: `machine · date · commit · N threads`,
    /// then `load L at start` where the load average is known.
    pub fn caption(&self) -> String {
        let load = self
            .load_average
            .map(|[one, five, fifteen]| {
                format!(" · load average {one:.2} {five:.2} {fifteen:.2} at start")
            })
            .unwrap_or_default();
        format!(
            "{} · {} · commit {} · {} thread{}{load}",
            self.machine,
            self.date,
            self.commit,
            self.threads,
            if self.threads == 1 { "" } else { "s" }
        )
    }
}

fn machine() -> String {
    let model = cpu(&std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let meminfo = std::fs::read_to_string("/proc/meminfo").unwrap_or_default();
    let memory_gib = meminfo
        .lines()
        .find_map(|l| l.strip_prefix("MemTotal:"))
        .and_then(|v| v.split_whitespace().next()?.parse::<f64>().ok())
        .map(|kib| kib / (1024.0 * 1024.0));
    let memory = memory_gib.map_or(String::new(), |gib| format!(", {gib:.0} GiB"));
    let kernel = std::fs::read_to_string("/proc/sys/kernel/osrelease")
        .map_or(String::new(), |release| {
            format!(", Linux {}", release.trim())
        });
    format!("{model}, {cores} cores{memory}{kernel}")
}

/// The first CPU of `/proc/cpuinfo`: its model name, then its family,
/// model and stepping where given, which tell apart generations sold
/// under one name ("Intel(R) Xeon(R) Processor" on many cloud machines).
fn cpu(cpuinfo: &str) -> String {
    let field = |key: &str| {
        cpuinfo.lines().find_map(|line| {
            let (name, value) = line.split_once(':')?;
            (name.trim() == key).then(|| value.trim())
        })
    };
    let name = field("model name").unwrap_or("unknown CPU");
    let ids: Vec<String> = [
        ("cpu family", "family"),
        ("model", "model"),
        ("stepping", "stepping"),
    ]
    .into_iter()
    .filter_map(|(key, label)| Some(format!("{label} {}", field(key)?)))
    .collect();
    if ids.is_empty() {
        name.to_string()
    } else {
        format!("{name} ({})", ids.join(", "))
    }
}

/// The 1, 5 and 15 minute load averages, where `/proc/loadavg` tells.
pub fn load_average() -> Option<[f64; 3]> {
    let text = std::fs::read_to_string("/proc/loadavg").ok()?;
    let mut values = text.split_whitespace().map(|v| v.parse::<f64>().ok());
    Some([values.next()??, values.next()??, values.next()??])
}

fn commit() -> String {
    let git = |args: &[&str]| {
        Command::new("git")
            .args(args)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
    };
    match git(&["rev-parse", "--short=12", "HEAD"]) {
        Some(hash) => {
            let dirty = git(&["status", "--porcelain", "--untracked-files=no"])
                .is_some_and(|s| !s.is_empty());
            if dirty { format!("{hash}+dirty") } else { hash }
        }
        None => "unknown".into(),
    }
}

fn utc_now() -> String {
    let secs = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    format_utc(secs)
}

/// Formats seconds since the Unix epoch as `YYYY-MM-DD HH:MM UTC`, with the
/// days-to-civil-date conversion of H. Hinnant, "chrono-Compatible Low-Level
/// Date Algorithms" (2013).
pub fn format_utc(secs: u64) -> String {
    let days = (secs / 86_400) as i64;
    let (hour, minute) = ((secs % 86_400) / 3600, (secs % 3600) / 60);
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let day_of_era = z - era * 146_097;
    let year_of_era =
        (day_of_era - day_of_era / 1460 + day_of_era / 36_524 - day_of_era / 146_096) / 365;
    let day_of_year = day_of_era - (365 * year_of_era + year_of_era / 4 - year_of_era / 100);
    let mp = (5 * day_of_year + 2) / 153;
    let day = day_of_year - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = year_of_era + era * 400 + (month <= 2) as i64;
    format!("{year:04}-{month:02}-{day:02} {hour:02}:{minute:02} UTC")
}

#[cfg(test)]
mod tests {
    use super::{RunMeta, cpu, format_utc};

    #[test]
    fn known_dates() {
        assert_eq!(format_utc(0), "1970-01-01 00:00 UTC");
        assert_eq!(format_utc(951_782_400), "2000-02-29 00:00 UTC");
        assert_eq!(format_utc(1_795_312_245), "2026-11-22 01:50 UTC");
    }

    #[test]
    fn the_caption_gives_the_load_where_it_is_known() {
        let mut meta = RunMeta {
            machine: "m".into(),
            date: "d".into(),
            commit: "c".into(),
            threads: 2,
            load_average: Some([0.25, 1.5, 2.0]),
        };
        assert_eq!(
            meta.caption(),
            "m · d · commit c · 2 threads · load average 0.25 1.50 2.00 at start"
        );
        meta.load_average = None;
        assert_eq!(meta.caption(), "m · d · commit c · 2 threads");
    }

    #[test]
    fn a_run_reads_the_load_where_linux_tells_it() {
        let meta = RunMeta::collect(1);
        let proc_tells = std::path::Path::new("/proc/loadavg").exists();
        assert_eq!(meta.load_average.is_some(), proc_tells);
        assert!(meta.load_average.into_iter().flatten().all(|l| l >= 0.0));
    }

    #[test]
    fn the_cpu_is_told_apart_by_family_model_and_stepping() {
        let cpuinfo = "processor\t: 0\ncpu family\t: 6\nmodel\t\t: 207\nmodel name\t: Intel(R) Xeon(R) Processor\nstepping\t: 2\n\nprocessor\t: 1\nmodel\t\t: 1\n";
        assert_eq!(
            cpu(cpuinfo),
            "Intel(R) Xeon(R) Processor (family 6, model 207, stepping 2)"
        );
        assert_eq!(cpu("model name\t: Some CPU\n"), "Some CPU");
        assert_eq!(cpu(""), "unknown CPU");
    }

    #[test]
    fn the_machine_names_the_cpu_and_the_kernel_where_linux_tells_them() {
        let machine = RunMeta::collect(1).machine;
        if let Ok(release) = std::fs::read_to_string("/proc/sys/kernel/osrelease") {
            assert!(
                machine.ends_with(&format!(", Linux {}", release.trim())),
                "{machine}"
            );
        }
        assert!(
            !machine.starts_with("unknown CPU") || !std::path::Path::new("/proc/cpuinfo").exists(),
            "{machine}"
        );
    }
}
