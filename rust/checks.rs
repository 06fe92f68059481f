//! Value checks shared by the kernels: each returns
//! [`CoreError::InvalidArgument`] naming the parameter, so the Python caller
//! gets a `ValueError` that starts with the parameter's name.
use crate::error::{CoreError, CoreResult};

/// `value` must be a positive finite number.
pub fn positive_finite(value: f64, param: &str) -> CoreResult<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(CoreError::invalid(
            param,
            format!("expected a positive finite number, got {value}"),
        ))
    }
}

/// `value` must be finite.
pub fn finite(value: f64, param: &str) -> CoreResult<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(CoreError::invalid(
            param,
            format!("expected a finite number, got {value}"),
        ))
    }
}

/// An output `step` (a positive number of pixels) and the shape of the grid
/// of every `step`-th pixel of a `rows x cols` image.
pub fn step_grid(step: usize, rows: usize, cols: usize) -> CoreResult<(usize, usize)> {
    if step == 0 {
        return Err(CoreError::invalid(
            "step",
            "expected a positive integer, got 0",
        ));
    }
    Ok((rows.div_ceil(step), cols.div_ceil(step)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checks_name_the_parameter() {
        assert_eq!(positive_finite(2.0, "z_scale"), Ok(2.0));
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let e = positive_finite(bad, "z_scale").unwrap_err().to_string();
            assert!(e.starts_with("z_scale: "), "{e}");
        }
        assert!(finite(f64::NEG_INFINITY, "z0").is_err());
        assert_eq!(step_grid(4, 9, 8), Ok((3, 2)));
        assert!(step_grid(0, 9, 8)
            .unwrap_err()
            .to_string()
            .starts_with("step: "));
    }
}
