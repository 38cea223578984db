//! Parallel loops over parts that cost unevenly, each part a job of its
//! own.
//!
//! Rayon splits a parallel iterator adaptively: a range no other worker
//! has taken is split only about log2(threads) times, then folded whole on
//! one worker (the thief-splitting `Splitter` of `rayon::iter::plumbing`).
//! Where the parts cost unevenly, as the rows and rays of a scene that
//! fills only the middle of the view do, one worker then waited while the
//! other folded a quarter of the work alone. On the 2-core Xeon the
//! monkey's primary rays, in chunks of 1,024, ran at 41 Mrays/s for ours
//! and 38 for Embree on two threads, 1.69 and 1.79 times their one-thread
//! speed; with one job per chunk, at 49 and 42 (1.99 and 1.94 times). Its
//! two-thread render took 48 ms instead of 57 with either. The Cornell box
//! and the dragons, which fill the view, gained 1-3%.

use rayon::iter::{IndexedParallelIterator, MaxLen};

/// `parts`, each a rayon job that any worker may take.
pub fn one_job_each<I: IndexedParallelIterator>(parts: I) -> MaxLen<I> {
    parts.with_max_len(1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    /// Each part is folded on its own, never with a neighbour: the fold
    /// starts afresh once for every part.
    #[test]
    fn every_part_is_folded_alone() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let parts: Vec<u32> = (0..1000).collect();
        let runs: Vec<usize> = pool.install(|| {
            one_job_each(parts.par_iter())
                .fold(|| 0, |count, _| count + 1)
                .collect()
        });
        assert_eq!(runs.len(), parts.len());
        assert!(runs.iter().all(|&run| run == 1), "{runs:?}");
    }
}
