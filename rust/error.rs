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
}
