//! Thread pools sized by the caller's `n_threads`.
//!
//! Every public kernel runs inside a rayon pool of its own size instead of the
//! global one, and pools are kept between calls (starting threads costs tens
//! of microseconds, as much as a whole small kernel):
//!
//! * a pool of every core (the default) is shared by the whole process:
//!   concurrent calls (Dask's threaded scheduler, Python threads with the GIL
//!   released) interleave their work on its threads instead of each starting
//!   one thread per core;
//! * a smaller pool (e.g. `n_threads=1` per Dask block) is kept per calling
//!   thread, so concurrent calls never queue on one another.
//!
//! A forked child does not have its parent's pool threads, so the pools
//! remember the process id and a child never touches the parent's: it builds
//! its own (rayon's global pool has no such guard, and a forked child's first
//! parallel call on it can hang), which matters for multiprocessing and Dask
//! workers. When the shared pools are busy (another thread is looking one up,
//! or a fork happened while it was), the call builds a private pool. The kept
//! threads sleep between calls; they make the process multi-threaded, so
//! Python >= 3.12 warns on `os.fork()` after a kernel call, as it does after
//! any threaded library call.
use std::cell::RefCell;
use std::sync::{Arc, Mutex};

use crate::error::{CoreError, CoreResult};

/// At most this many threads per available core (the Python layer checks
/// the same cap first, see `_validation.check_n_threads`).
pub const MAX_THREADS_PER_CORE: usize = 4;

/// The cap never goes below this many threads (so a thread count chosen on
/// a larger machine still runs on a small one).
pub const MIN_THREAD_CAP: usize = 16;

/// The largest `n_threads` accepted: [`MAX_THREADS_PER_CORE`] times the
/// cores, at least [`MIN_THREAD_CAP`].
pub fn max_threads() -> usize {
    (MAX_THREADS_PER_CORE * resolve_threads(None)).max(MIN_THREAD_CAP)
}

/// Resolve `n_threads`: `None` or `Some(0)` means all available cores
/// (looked up once per process: on Linux the lookup reads cgroup files,
/// which costs as much as a small kernel).
pub fn resolve_threads(n_threads: Option<usize>) -> usize {
    static CORES: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    match n_threads {
        Some(n) if n > 0 => n,
        _ => *CORES.get_or_init(|| {
            std::thread::available_parallelism()
                .map(|n| n.get())
                .unwrap_or(1)
        }),
    }
}

/// Pools kept per thread count, with the process that built them.
struct PoolCache {
    pid: u32,
    pools: Vec<(usize, Arc<rayon::ThreadPool>)>,
}

thread_local! {
    /// The calling thread's pools of fewer threads than cores.
    static POOLS: RefCell<Option<PoolCache>> = const { RefCell::new(None) };
}

/// The process's pools of at least as many threads as cores.
static SHARED: Mutex<Option<PoolCache>> = Mutex::new(None);

/// At most this many thread counts keep a pool (per calling thread, and shared).
const MAX_POOLS: usize = 4;

fn build_pool(n: usize) -> CoreResult<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build()
        .map_err(|e| {
            CoreError::System(format!(
                "n_threads: the operating system refused to start {n} threads ({e}); \
                 use fewer threads (n_threads=None uses one per core)"
            ))
        })
}

/// A kept pool of `n` threads, built on first use: shared by the process
/// when `n` is at least the number of cores, else the calling thread's.
fn pool_of(n: usize) -> CoreResult<Arc<rayon::ThreadPool>> {
    let pid = std::process::id();
    let private = || build_pool(n).map(Arc::new);
    if n >= resolve_threads(None) {
        return match SHARED.try_lock() {
            Ok(mut cache) => lookup(&mut cache, pid, n),
            Err(_) => private(), // busy, or held by another thread at a fork
        };
    }
    POOLS
        .try_with(|cell| match cell.try_borrow_mut() {
            Ok(mut cache) => lookup(&mut cache, pid, n),
            Err(_) => private(), // not reached: the borrow ends before a kernel runs
        })
        .unwrap_or_else(|_| private()) // the thread is exiting
}

/// Find or build the pool of `n` threads in `cache`, for process `pid`.
fn lookup(cache: &mut Option<PoolCache>, pid: u32, n: usize) -> CoreResult<Arc<rayon::ThreadPool>> {
    let cache = cache.get_or_insert_with(|| PoolCache {
        pid,
        pools: Vec::new(),
    });
    if cache.pid != pid {
        // a forked child: the parent's worker threads do not exist here, so
        // its pools are neither used nor dropped (dropping signals them)
        for (_, p) in cache.pools.drain(..) {
            std::mem::forget(p);
        }
        cache.pid = pid;
    }
    if let Some(i) = cache.pools.iter().position(|(k, _)| *k == n) {
        // most recently used last: the eviction below drops the least recent
        let entry = cache.pools.remove(i);
        cache.pools.push(entry);
        return Ok(cache.pools[cache.pools.len() - 1].1.clone());
    }
    let pool = Arc::new(build_pool(n)?);
    if cache.pools.len() >= MAX_POOLS {
        cache.pools.remove(0);
    }
    cache.pools.push((n, pool.clone()));
    Ok(pool)
}

/// Run `f` in a rayon pool of `n_threads` threads. A panic inside `f` is
/// caught and turned into [`CoreError::Internal`], so it never unwinds into
/// the caller (and never reaches Python).
pub fn run_in_pool<T, F>(n_threads: Option<usize>, f: F) -> CoreResult<T>
where
    T: Send,
    F: FnOnce() -> CoreResult<T> + Send,
{
    let n = resolve_threads(n_threads);
    if n > max_threads() {
        return Err(CoreError::invalid(
            "n_threads",
            format!(
                "expected at most {} ({MAX_THREADS_PER_CORE} per available core, at least \
                 {MIN_THREAD_CAP}), got {n}",
                max_threads()
            ),
        ));
    }
    let run = || std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
    // already on a worker of a pool of this size (a kernel calling a kernel):
    // run here rather than keep pools in the worker's thread
    let result = if rayon::current_thread_index().is_some() && rayon::current_num_threads() == n {
        run()
    } else {
        pool_of(n)?.install(run)
    };
    match result {
        Ok(r) => r,
        Err(payload) => {
            let msg = if let Some(s) = payload.downcast_ref::<&str>() {
                (*s).to_string()
            } else if let Some(s) = payload.downcast_ref::<String>() {
                s.clone()
            } else {
                "unknown panic".to_string()
            };
            Err(CoreError::Internal(msg))
        }
    }
}

/// The address of a buffer that the tasks of one parallel loop share, for
/// loops whose tasks write disjoint cells and read only cells no task writes
/// (a checkerboard pass, rows that each own their cells).
///
/// Making one is safe; every dereference of [`SharedMut::get`] is `unsafe`
/// and its caller states why no two tasks touch one cell mutably and why the
/// cell lies inside the buffer, which must outlive the loop.
#[derive(Debug, Clone, Copy)]
pub struct SharedMut<T>(*mut T);

// SAFETY: the value is only an address; sending it to another thread is
// sound because every dereference is an `unsafe` block of the caller, under
// the disjointness rule it states (see the type's documentation).
unsafe impl<T: Send> Send for SharedMut<T> {}
// SAFETY: as for Send: sharing the address allows nothing by itself.
unsafe impl<T: Send> Sync for SharedMut<T> {}

impl<T> SharedMut<T> {
    /// The address of `buf`'s first element.
    pub fn new(buf: &mut [T]) -> Self {
        SharedMut(buf.as_mut_ptr())
    }

    /// The shared address.
    #[inline]
    pub fn get(&self) -> *mut T {
        self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pool_runs_and_catches_panics() {
        assert_eq!(
            run_in_pool(Some(2), || Ok(rayon::current_num_threads())).unwrap(),
            2
        );
        let r: CoreResult<()> = run_in_pool(Some(1), || panic!("boom"));
        assert_eq!(r, Err(CoreError::Internal("boom".into())));
        // the pool survives a caught panic and is reused
        assert_eq!(
            run_in_pool(Some(1), || Ok(rayon::current_num_threads())).unwrap(),
            1
        );
    }

    #[test]
    fn too_many_threads_is_a_clear_error() {
        let r: CoreResult<()> = run_in_pool(Some(max_threads() + 1), || Ok(()));
        match r {
            Err(CoreError::InvalidArgument { param, .. }) => assert_eq!(param, "n_threads"),
            other => panic!("expected InvalidArgument, got {other:?}"),
        }
        assert_eq!(run_in_pool(Some(max_threads()), || Ok(1)).unwrap(), 1);
    }

    #[test]
    fn pools_are_kept_per_thread_count_and_process() {
        let mut cache = None;
        let a = lookup(&mut cache, 10, 3).unwrap();
        assert_eq!(a.current_num_threads(), 3);
        assert!(Arc::ptr_eq(&a, &lookup(&mut cache, 10, 3).unwrap()));
        let b = lookup(&mut cache, 10, 2).unwrap();
        assert_eq!(b.current_num_threads(), 2);
        assert!(!Arc::ptr_eq(&a, &b));
        // another process id (a forked child) never gets the parent's pools
        let c = lookup(&mut cache, 11, 3).unwrap();
        assert!(!Arc::ptr_eq(&a, &c));
        assert_eq!(cache.as_ref().unwrap().pools.len(), 1);
        // at most MAX_POOLS thread counts are kept
        for n in 1..=MAX_POOLS + 2 {
            lookup(&mut cache, 11, n).unwrap();
        }
        assert_eq!(cache.as_ref().unwrap().pools.len(), MAX_POOLS);
        // the least recently used count is evicted, not the first built
        let mut cache = None;
        let keep = lookup(&mut cache, 12, 1).unwrap();
        for n in 2..=MAX_POOLS {
            lookup(&mut cache, 12, n).unwrap();
        }
        assert!(Arc::ptr_eq(&keep, &lookup(&mut cache, 12, 1).unwrap()));
        lookup(&mut cache, 12, MAX_POOLS + 1).unwrap(); // evicts 2
        assert!(Arc::ptr_eq(&keep, &lookup(&mut cache, 12, 1).unwrap()));
        assert!(cache.as_ref().unwrap().pools.iter().all(|(k, _)| *k != 2));
    }

    #[test]
    fn a_kernel_inside_a_pool_of_its_size_runs_in_place() {
        let outer = run_in_pool(Some(3), || {
            let idx = rayon::current_thread_index();
            run_in_pool(Some(3), move || Ok((idx, rayon::current_thread_index())))
        })
        .unwrap();
        assert_eq!(outer.0, outer.1);
    }
}
