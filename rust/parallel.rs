//! Thread pools sized by the caller's `n_threads`.
//!
//! Every public kernel runs inside a rayon pool of its own size instead of the
//! global one. Each calling thread keeps its pools, one per thread count
//! (starting threads costs tens of microseconds, as much as a whole small
//! kernel): concurrent calls from several threads (Dask's threaded scheduler,
//! Python threads with the GIL released) never share or queue on one pool, so
//! `n_threads` is per call, as before. A forked child does not have its
//! parent's pool threads, so the pools remember the process id and a child
//! never touches the parent's: it builds its own (rayon's global pool has no
//! such guard, and a forked child's first parallel call on it can hang),
//! which matters for multiprocessing and Dask workers. The kept threads sleep
//! between calls; they make the process multi-threaded, so Python >= 3.12
//! warns on `os.fork()` after a kernel call, as it does after any threaded
//! library call.
use std::cell::RefCell;
use std::sync::Arc;

use crate::error::{CoreError, CoreResult};

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
    /// The calling thread's pools.
    static POOLS: RefCell<Option<PoolCache>> = const { RefCell::new(None) };
}

/// At most this many thread counts keep a pool per calling thread.
const MAX_POOLS: usize = 4;

fn build_pool(n: usize) -> CoreResult<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build()
        .map_err(|e| CoreError::Internal(format!("cannot start a thread pool of {n}: {e}")))
}

/// The calling thread's pool of `n` threads, built on first use.
fn pool_of(n: usize) -> CoreResult<Arc<rayon::ThreadPool>> {
    POOLS
        .try_with(|cell| match cell.try_borrow_mut() {
            Ok(mut cache) => lookup(&mut cache, std::process::id(), n),
            // re-entered from inside a kernel: a private pool
            Err(_) => build_pool(n).map(Arc::new),
        })
        // the thread is exiting: a private pool
        .unwrap_or_else(|_| build_pool(n).map(Arc::new))
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
    if let Some((_, p)) = cache.pools.iter().find(|(k, _)| *k == n) {
        return Ok(p.clone());
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
    let pool = pool_of(n)?;
    let result = pool.install(|| std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)));
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
    }
}
