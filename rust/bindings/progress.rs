//! The Python face of `crate::progress`: a counter object any binding can
//! take as `progress=` and hand to its kernel.
use crate::progress::Progress;
use pyo3::prelude::*;
use std::sync::Arc;

/// A work counter a kernel ticks while it runs with the GIL released:
/// `done` and `total` can be read from another Python thread meanwhile.
#[pyclass(frozen, module = "fractalgeo_rs._core")]
pub struct ProgressCounter {
    inner: Arc<Progress>,
}

#[pymethods]
impl ProgressCounter {
    #[new]
    fn new() -> Self {
        Self {
            inner: Arc::new(Progress::new()),
        }
    }

    /// Units of work done so far.
    #[getter]
    fn done(&self) -> u64 {
        self.inner.done()
    }

    /// Units of work announced so far by the kernels given this counter.
    #[getter]
    fn total(&self) -> u64 {
        self.inner.total()
    }
}

pub(crate) fn counter(p: Option<&Bound<'_, ProgressCounter>>) -> Option<Arc<Progress>> {
    p.map(|c| Arc::clone(&c.get().inner))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<ProgressCounter>()
}
