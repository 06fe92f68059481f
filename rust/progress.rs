//! A work counter that kernels tick while they run, read from another thread.
//!
//! Plain Rust (no PyO3): a kernel that can report takes `Option<&Progress>`,
//! sets the total it will reach ([`Progress::add_total`]) and ticks as it
//! goes ([`Progress::tick`], one relaxed atomic add). Reading it never
//! changes the work, so results are the same with and without a counter.
use std::sync::atomic::{AtomicU64, Ordering};

/// Units of work done out of a total (both atomics: `Sync`, cheap to tick).
#[derive(Debug, Default)]
pub struct Progress {
    done: AtomicU64,
    total: AtomicU64,
}

impl Progress {
    /// A counter at 0 of 0.
    pub fn new() -> Self {
        Self::default()
    }

    /// Add `n` units to the total (a kernel announces its work).
    pub fn add_total(&self, n: u64) {
        self.total.fetch_add(n, Ordering::Relaxed);
    }

    /// Record `n` more units done.
    pub fn tick(&self, n: u64) {
        self.done.fetch_add(n, Ordering::Relaxed);
    }

    /// Units done so far.
    pub fn done(&self) -> u64 {
        self.done.load(Ordering::Relaxed)
    }

    /// Units announced so far.
    pub fn total(&self) -> u64 {
        self.total.load(Ordering::Relaxed)
    }
}

/// `p.add_total(n)` when there is a counter.
pub fn add_total(p: Option<&Progress>, n: u64) {
    if let Some(p) = p {
        p.add_total(n);
    }
}

/// `p.tick(n)` when there is a counter.
pub fn tick(p: Option<&Progress>, n: u64) {
    if let Some(p) = p {
        p.tick(n);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_from_many_threads_add_up() {
        use rayon::prelude::*;
        let p = Progress::new();
        p.add_total(1000);
        (0..1000u64).into_par_iter().for_each(|_| p.tick(1));
        assert_eq!((p.done(), p.total()), (1000, 1000));
        tick(None, 5);
        add_total(None, 5);
    }
}
