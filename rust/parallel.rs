//! Thread pools sized by the caller's `n_threads`.
//!
//! Every public kernel runs inside a freshly built rayon pool instead of the
//! global one. Building a pool costs tens of microseconds, and a fresh pool is
//! safe after `fork()` (rayon's global pool is not: a forked child's first
//! parallel call can hang), which matters for multiprocessing and Dask workers.
use crate::error::{CoreError, CoreResult};

/// Resolve `n_threads`: `None` or `Some(0)` means all available cores.
pub fn resolve_threads(n_threads: Option<usize>) -> usize {
    match n_threads {
        Some(n) if n > 0 => n,
        _ => std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1),
    }
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
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build()
        .map_err(|e| CoreError::Internal(format!("cannot start a thread pool of {n}: {e}")))?;
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
    }
}
