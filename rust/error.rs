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
    /// A file or folder that does not exist. Maps to `FileNotFoundError`.
    #[error("{0}")]
    NotFound(String),
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
    /// An I/O failure described by `context` (e.g. "cannot open x.png"):
    /// [`CoreError::NotFound`] when the file does not exist, else [`CoreError::Io`].
    pub fn from_io(context: impl std::fmt::Display, e: &std::io::Error) -> Self {
        let message = format!("{context}: {e}");
        if e.kind() == std::io::ErrorKind::NotFound {
            CoreError::NotFound(message)
        } else {
            CoreError::Io(message)
        }
    }

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_file_is_not_found_and_other_io_errors_are_io() {
        let missing = std::fs::File::open("/nonexistent-dir/no-such-file.png").unwrap_err();
        assert_eq!(
            CoreError::from_io("cannot open x", &missing),
            CoreError::NotFound(format!("cannot open x: {missing}"))
        );
        let denied = std::io::Error::from(std::io::ErrorKind::PermissionDenied);
        assert!(matches!(CoreError::from_io("x", &denied), CoreError::Io(_)));
    }

    #[test]
    fn reading_a_missing_image_or_exr_says_not_found() {
        let p = std::path::Path::new("/nonexistent-dir/a.png");
        assert!(matches!(
            crate::io::image_io::read_image(p),
            Err(CoreError::NotFound(_))
        ));
        let p = std::path::Path::new("/nonexistent-dir/a.exr");
        assert!(matches!(
            crate::io::exr_io::read_exr_gray(p),
            Err(CoreError::NotFound(_))
        ));
    }
}
