//! The run every command works in, made once by `main` from the shared
//! `--threads`, `--kernel` and `--embree-isa` arguments and the command's
//! form, then handed down: the worker threads, Embree's device and our
//! kernel ([`Workers`], [`InstructionSets`]), the stamp taken when
//! the run began ([`RunMeta`]) and how much of everything to run
//! ([`Form`]). Nothing below makes its own (as pbrt-v4 reads its options
//! once in `InitPBRT`); `perf`, which times several thread counts, asks
//! the run for the workers of each ([`RunContext::workers_for`]).

use crate::backends::BuildContext;
use crate::parallel::{InstructionSets, Workers};
use crate::results::RunMeta;
use raycheck_reference::ThreadLimit;
use serde::{Deserialize, Serialize};
use std::sync::{Arc, Mutex};

/// How much of everything a command runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Form {
    /// Small scenes, few rays and runs: a smoke run of a minute or two.
    Quick,
    /// What fits a laptop: the report's default (within 15 minutes on two
    /// cores and 4 GB), each part's quick form where its full one does not
    /// fit, and no scene beyond a million triangles.
    Standard,
    /// Everything in full, the 13.9M-triangle dragon included.
    Full,
}

impl Form {
    /// The form of a command's `--quick` and `--full` flags, `default`
    /// when neither is given.
    pub fn from_flags(quick: bool, full: bool, default: Form) -> Form {
        match (quick, full) {
            (true, _) => Form::Quick,
            (_, true) => Form::Full,
            _ => default,
        }
    }

    pub fn is_quick(self) -> bool {
        self == Form::Quick
    }

    pub fn is_full(self) -> bool {
        self == Form::Full
    }
}

/// What a run is made from: the command line's shared arguments.
#[derive(Clone, Copy, Debug)]
pub struct RunOptions {
    /// Worker threads; every core when `None`.
    pub threads: Option<usize>,
    pub form: Form,
    pub sets: InstructionSets,
}

/// The run: its workers, stamp and form.
pub struct RunContext {
    requested_threads: Option<usize>,
    form: Form,
    sets: InstructionSets,
    meta: RunMeta,
    workers: Arc<Workers>,
    /// Workers at other thread counts, made when first asked for.
    other_workers: Mutex<Vec<Arc<Workers>>>,
    /// oneTBB held to the run's thread count, so that Embree devices made
    /// and released during the run leave no worker spinning.
    _thread_limit: Option<ThreadLimit>,
}

impl RunContext {
    /// Starts a run: its stamp first (so its date and load average are the
    /// start's), then its workers and Embree's device.
    pub fn new(options: RunOptions) -> anyhow::Result<Self> {
        let workers = Workers::new(options.threads, options.sets)?;
        let meta = RunMeta::collect(workers.threads());
        let thread_limit = ThreadLimit::hold(workers.threads());
        Ok(Self {
            requested_threads: options.threads,
            form: options.form,
            sets: options.sets,
            meta,
            workers: Arc::new(workers),
            other_workers: Mutex::new(Vec::new()),
            _thread_limit: thread_limit,
        })
    }

    pub fn form(&self) -> Form {
        self.form
    }

    /// Our kernel and Embree's widest instruction set, at every thread
    /// count.
    pub fn sets(&self) -> InstructionSets {
        self.sets
    }

    /// The run's stamp: machine, date, commit, threads, load at the start.
    pub fn meta(&self) -> &RunMeta {
        &self.meta
    }

    /// The run's worker count.
    pub fn threads(&self) -> usize {
        self.workers.threads()
    }

    /// The run's workers.
    pub fn workers(&self) -> &Workers {
        &self.workers
    }

    /// Runs `work` on the run's workers.
    pub fn install<R: Send>(&self, work: impl FnOnce() -> R + Send) -> R {
        self.workers.install(work)
    }

    /// What backends built on the run's workers use.
    pub fn build_context(&self) -> BuildContext<'_> {
        self.workers.build_context()
    }

    /// Workers at `threads` threads: the run's own at its count, others
    /// made once and kept for the rest of the run.
    pub fn workers_for(&self, threads: usize) -> anyhow::Result<Arc<Workers>> {
        if threads == self.threads() {
            return Ok(Arc::clone(&self.workers));
        }
        let mut others = self
            .other_workers
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        if let Some(workers) = others.iter().find(|w| w.threads() == threads) {
            return Ok(Arc::clone(workers));
        }
        let workers = Arc::new(Workers::new(Some(threads), self.sets)?);
        others.push(Arc::clone(&workers));
        Ok(workers)
    }

    /// The thread counts a timing command measures: the one `--threads`
    /// gave, else one thread and every core.
    pub fn thread_counts(&self) -> Vec<usize> {
        match self.requested_threads {
            Some(_) => vec![self.threads()],
            None if self.threads() > 1 => vec![1, self.threads()],
            None => vec![1],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn workers_are_made_once_per_thread_count() {
        let run = RunContext::new(RunOptions {
            threads: Some(2),
            form: Form::Quick,
            sets: InstructionSets::default(),
        })
        .unwrap();
        assert_eq!(run.threads(), 2);
        assert_eq!(run.meta().threads, 2);
        assert_eq!(run.thread_counts(), [2]);
        let one = run.workers_for(1).unwrap();
        assert_eq!(one.threads(), 1);
        assert!(Arc::ptr_eq(&one, &run.workers_for(1).unwrap()));
        assert!(Arc::ptr_eq(&run.workers, &run.workers_for(2).unwrap()));
    }

    #[test]
    fn flags_give_the_form() {
        assert_eq!(Form::from_flags(true, false, Form::Full), Form::Quick);
        assert_eq!(Form::from_flags(false, true, Form::Standard), Form::Full);
        assert_eq!(
            Form::from_flags(false, false, Form::Standard),
            Form::Standard
        );
    }
}
