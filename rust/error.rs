//! One error type for the whole core. The bindings map each variant to one
//! Python exception class (`From<CoreError> for PyErr` in `bindings`).
use thiserror::Error;

/// Errors raised by the kernels.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum CoreError {
    /// A parameter has a value the kernel cannot use. Maps to `ValueError`.
    #[error("{param}: {message}")]
    InvalidArgument { param: String, message: String },
    /// An input/output failure (file missing, undecodable, unwritable). Maps to `OSError`.
    #[error("{0}")]
    Io(String),
    /// A buffer whose size grows with `param` could not be allocated (or its
    /// size overflows). Maps to `MemoryError`.
    #[error("{param}: cannot allocate {bytes} bytes ({gib:.2} GiB) of working memory", gib = *bytes as f64 / (1u64 << 30) as f64)]
    OutOfMemory { param: String, bytes: u128 },
    /// The operating system refused a resource (e.g. threads for a pool).
    /// Maps to `OSError`.
    #[error("{0}")]
    System(String),
    /// A bug: an invariant of the kernel did not hold. Maps to `RuntimeError`.
    #[error("internal error: {0}")]
    Internal(String),
}

/// Shorthand for results of the core.
pub type CoreResult<T> = Result<T, CoreError>;

impl CoreError {
    /// Build an [`CoreError::InvalidArgument`] naming the parameter.
    pub fn invalid(param: &str, message: impl Into<String>) -> Self {
        CoreError::InvalidArgument {
            param: param.to_string(),
            message: message.into(),
        }
    }

    /// Build an [`CoreError::OutOfMemory`] for `count` elements of `elem`
    /// bytes each, sized by the parameter `param`.
    pub fn out_of_memory(param: &str, count: usize, elem: usize) -> Self {
        CoreError::OutOfMemory {
            param: param.to_string(),
            bytes: count as u128 * elem as u128,
        }
    }
}
