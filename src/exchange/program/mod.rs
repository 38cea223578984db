//! Tracers run as programs, inside any command that checks backends.
//!
//! A program answers through files, so a command that names one runs
//! twice ([`with_programs`]): first with a stand-in for each program that
//! answers as the checked backend does and records the meshes and rays it
//! is asked ([`session`]); then every program traces those rays in
//! batches ([`runner`]); then the command runs again with the programs'
//! answers replayed. The rays a command asks depend only on the checked
//! backend's answers (every other backend's are compared, never followed),
//! so the second run asks exactly the recorded rays. A program that fails
//! (cannot start, exits with an error, runs past its time limit, writes a
//! bad file) is left out of the second run, and its error is reported with
//! the rest of the results.

pub mod runner;
pub mod session;

use crate::adapters::ProgramCommand;
use crate::backends::{BackendName, ProgramKind};
use crate::results::{Cell, Table, Tone};
use anyhow::Context;
use runner::Workload;
use serde::Serialize;
use session::{Recording, Replaying, SharedRecord};
use std::sync::Arc;
use std::sync::atomic::Ordering;

/// What one program did in a command.
#[derive(Clone, Debug, Serialize)]
pub struct ProgramRun {
    pub name: String,
    pub workload: Workload,
    /// Why it was left out, when it failed.
    pub error: Option<String>,
}

/// A command's result with what its programs did.
pub struct WithPrograms<T> {
    pub value: T,
    pub programs: Vec<ProgramRun>,
}

/// Runs `work` over the backends `names`, the programs among them
/// answering from files (see the module's note). `work` may run twice; its
/// first result is dropped. The checked backend (the first) must run in
/// process.
pub fn with_programs<T>(
    names: &[BackendName],
    work: impl Fn(&[BackendName]) -> anyhow::Result<T>,
    progress: &dyn Fn(&str),
) -> anyhow::Result<WithPrograms<T>> {
    if !names.iter().any(|name| name.program().is_some()) {
        return Ok(WithPrograms {
            value: work(names)?,
            programs: Vec::new(),
        });
    }
    let checked = names.first().context("no backends")?;
    anyhow::ensure!(
        checked.program().is_none(),
        "{checked} is a program, so it cannot be the checked backend (the first): the rays \
         a command asks follow the checked backend's answers, and a program answers only \
         afterwards. Put an in-process backend first (e.g. ours,{checked}), or trace the \
         exported rays with it and judge its hits file"
    );
    let records: Vec<Option<SharedRecord>> = names
        .iter()
        .map(|name| name.program().map(|_| SharedRecord::default()))
        .collect();
    let recording: Vec<BackendName> = names
        .iter()
        .zip(&records)
        .map(|(name, record)| match (name.program(), record) {
            (Some(program), Some(record)) => BackendName::shared(Arc::new(Recording {
                program: program.clone(),
                checked: checked.clone(),
                record: Arc::clone(record),
            })),
            _ => name.clone(),
        })
        .collect();
    progress("recording the rays the programs are asked");
    work(&recording)?;
    let mut programs = Vec::new();
    let mut replaying = Vec::new();
    for (name, record) in names.iter().zip(&records) {
        let (Some(program), Some(record)) = (name.program(), record) else {
            replaying.push(name.clone());
            continue;
        };
        let outcome = run_program(program, record, progress);
        let (workload, error) = match outcome {
            Ok(workload) => (workload, None),
            Err(error) => (Workload::default(), Some(format!("{error:#}"))),
        };
        if error.is_none() {
            replaying.push(BackendName::shared(Arc::new(Replaying {
                program: program.clone(),
                record: Arc::clone(record),
            })));
        }
        programs.push(ProgramRun {
            name: name.to_string(),
            workload,
            error,
        });
    }
    progress("replaying the programs' answers");
    let value = work(&replaying)?;
    for (run, record) in programs.iter_mut().zip(records.iter().flatten()) {
        let unrecorded = record
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .unrecorded
            .load(Ordering::Relaxed);
        if unrecorded > 0 && run.error.is_none() {
            run.error = Some(format!(
                "{unrecorded} rays were asked again that had not been recorded: \
                 the command asked other rays the second time"
            ));
        }
    }
    Ok(WithPrograms { value, programs })
}

/// Sets the program up and runs it over what it was asked.
fn run_program(
    program: &ProgramKind,
    record: &SharedRecord,
    progress: &dyn Fn(&str),
) -> anyhow::Result<Workload> {
    let command = prepare(program)?;
    runner::answer_recorded(program, &command, record, progress)
}

/// The command that runs `program`, once whatever it needs is set up in
/// raycheck's cache (an adapter's Python environment or compiled
/// program).
pub fn prepare(program: &ProgramKind) -> anyhow::Result<ProgramCommand> {
    let cache = crate::scene::assets::cache_dir().map_err(anyhow::Error::msg)?;
    program
        .launch
        .prepare(&cache)
        .with_context(|| format!("setting up {}", program.name()))
}

/// What the programs of a command did, a row each: their workload, wall
/// time and, for those left out, why.
pub fn table(runs: &[ProgramRun], caption: &str) -> Table {
    let mut table = Table::new(
        "Programs: rays traced through files (wall time shown, not compared)",
        &["program", "meshes", "rays", "batches", "wall s", "status"],
        caption,
    );
    for run in runs {
        let w = &run.workload;
        table.push([
            Cell::from(run.name.as_str()),
            w.meshes.to_string().into(),
            w.rays.to_string().into(),
            w.batches.to_string().into(),
            format!("{:.1}", w.seconds).into(),
            match &run.error {
                Some(_) => Cell::new("failed (why: below)", Tone::Bad),
                None => Cell::new("ran", Tone::Good),
            },
        ]);
    }
    table
}

impl<T> WithPrograms<T> {
    /// The programs left out, with why: what makes a command exit 2 once
    /// it has printed the rest.
    pub fn failures(&self) -> Vec<&ProgramRun> {
        self.programs
            .iter()
            .filter(|run| run.error.is_some())
            .collect()
    }
}
