//! Summed-area tables and the argument checks shared by the moving-window
//! kernels.
use crate::error::{CoreError, CoreResult};

/// Summed-area table `(rows + 1) x (cols + 1)` of row-major `values`.
pub(crate) fn sat(values: &[f64], rows: usize, cols: usize) -> Vec<f64> {
    let w = cols + 1;
    let mut s = vec![0.0f64; (rows + 1) * w];
    for r in 0..rows {
        let mut run = 0.0;
        for c in 0..cols {
            run += values[r * cols + c];
            s[(r + 1) * w + c + 1] = s[r * w + c + 1] + run;
        }
    }
    s
}

/// [`sat`] of the values `f(r, c)`, written into `s` (see [`sats_into`]).
pub(crate) fn sat_into(
    s: &mut Vec<f64>,
    rows: usize,
    cols: usize,
    f: impl Fn(usize, usize) -> f64,
) {
    sats_into([s], rows, cols, |r, c| [f(r, c)]);
}

/// [`sat`] of each of the `N` values of `f(r, c)`, in one pass (for values
/// that share their computation), written into reusable buffers: each is
/// resized, its row 0 and column 0 zeroed and every other entry written, so
/// a reused buffer gives the same table without a zeroing pass.
pub(crate) fn sats_into<const N: usize>(
    tables: [&mut Vec<f64>; N],
    rows: usize,
    cols: usize,
    f: impl Fn(usize, usize) -> [f64; N],
) {
    let w = cols + 1;
    let mut tables = tables;
    for s in tables.iter_mut() {
        s.resize((rows + 1) * w, 0.0);
        s[..w].fill(0.0);
        for r in 1..=rows {
            s[r * w] = 0.0;
        }
    }
    for r in 0..rows {
        let mut run = [0.0f64; N];
        for c in 0..cols {
            let v = f(r, c);
            for ((s, acc), x) in tables.iter_mut().zip(run.iter_mut()).zip(v) {
                *acc += x;
                s[(r + 1) * w + c + 1] = s[r * w + c + 1] + *acc;
            }
        }
    }
}

/// Sum over rows `[r0, r1)` x cols `[c0, c1)` of a table of row width `w`
/// (`cols + 1`); empty ranges sum to 0.
#[inline]
pub(crate) fn rect(s: &[f64], w: usize, r0: usize, r1: usize, c0: usize, c1: usize) -> f64 {
    if r1 <= r0 || c1 <= c0 {
        return 0.0;
    }
    s[r1 * w + c1] - s[r0 * w + c1] - s[r1 * w + c0] + s[r0 * w + c0]
}

/// Check the image buffer, the window (odd, >= 3, not larger than the image)
/// and `min_valid` (a fraction); returns the fewest valid pixels a window needs.
pub(crate) fn check_window(
    z_len: usize,
    rows: usize,
    cols: usize,
    w: usize,
    min_valid: f64,
) -> CoreResult<f64> {
    if rows * cols == 0 || z_len != rows * cols {
        return Err(CoreError::invalid("image", "image is empty"));
    }
    if w < 3 || w % 2 == 0 {
        return Err(CoreError::invalid(
            "window_size",
            format!("expected an odd integer >= 3, got {w}"),
        ));
    }
    if w > rows.max(cols) {
        return Err(CoreError::invalid(
            "window_size",
            format!("window {w} is larger than the image ({rows} x {cols})"),
        ));
    }
    if !(0.0..=1.0).contains(&min_valid) {
        return Err(CoreError::invalid(
            "min_valid",
            format!("expected a fraction in [0, 1], got {min_valid}"),
        ));
    }
    Ok((min_valid * (w * w) as f64).ceil().max(1.0))
}

/// Output rows per band: a function of the window only (never of the thread
/// count), at least 64 and four windows, so the halo is a small overhead.
pub(crate) fn band_rows(w: usize) -> usize {
    64usize.max(4 * w)
}

/// Least-squares slope and r² of `ys` against `xs` (with `xm` the mean of
/// `xs` and `sxx` the sum of its squared deviations); r² is 1 when `ys` is flat.
#[inline]
pub(crate) fn line_fit(xs: &[f64], xm: f64, sxx: f64, ys: &[f64]) -> (f64, f64) {
    let ym = ys.iter().sum::<f64>() / ys.len() as f64;
    let sxy: f64 = xs.iter().zip(ys).map(|(x, y)| (x - xm) * (y - ym)).sum();
    let syy: f64 = ys.iter().map(|y| (y - ym) * (y - ym)).sum();
    let r2 = if syy > 0.0 {
        sxy * sxy / (sxx * syy)
    } else {
        1.0
    };
    (sxy / sxx, r2)
}

/// `ln` of the scales, their mean and the sum of squared deviations: the x
/// axis of a log-log fit, for [`line_fit`].
pub(crate) fn log_axis(scales: &[usize]) -> (Vec<f64>, f64, f64) {
    let xs: Vec<f64> = scales.iter().map(|&v| (v as f64).ln()).collect();
    let xm = xs.iter().sum::<f64>() / xs.len() as f64;
    let sxx = xs.iter().map(|x| (x - xm) * (x - xm)).sum();
    (xs, xm, sxx)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reused_dirty_buffers_give_the_fresh_tables() {
        let (rows, cols) = (7usize, 5usize);
        let v: Vec<f64> = (0..rows * cols)
            .map(|k| (k * 37 % 11) as f64 - 3.0)
            .collect();
        let fresh = sat(&v, rows, cols);
        let neg: Vec<f64> = v.iter().map(|x| -x).collect();
        let fresh_neg = sat(&neg, rows, cols);
        // larger and smaller dirty buffers, and a same-size one of another shape
        for len in [0usize, 10, 48, 500] {
            let (mut a, mut b) = (vec![9.5; len], vec![-4.0; len]);
            sats_into([&mut a, &mut b], rows, cols, |r, c| {
                [v[r * cols + c], -v[r * cols + c]]
            });
            assert_eq!((&a, &b), (&fresh, &fresh_neg), "len {len}");
            let mut s = vec![1.0; len];
            sat_into(&mut s, rows, cols, |r, c| v[r * cols + c]);
            assert_eq!(s, fresh);
        }
    }
}
