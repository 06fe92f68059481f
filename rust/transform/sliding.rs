//! Sliding minimum and maximum over rectangles (van Herk 1992; Gil and
//! Werman 1993): about three comparisons per sample and pass, whatever the
//! rectangle, so a box-count field costs O(1) per pixel.

/// Row `cur` (offset) of running minima and maxima `run` over the rows of
/// `src`: the source row itself at a block's first row (`from` is `None`),
/// else its extrema with the running row at offset `from`; rows of `n`.
#[inline]
fn fold_row(
    run: (&mut [f64], &mut [f64]),
    src: (&[f64], &[f64]),
    cur: usize,
    from: Option<usize>,
    n: usize,
) {
    let ((lo, hi), (slo, shi)) = (run, src);
    match from {
        None => {
            lo[cur..cur + n].copy_from_slice(&slo[cur..cur + n]);
            hi[cur..cur + n].copy_from_slice(&shi[cur..cur + n]);
        }
        Some(p) => {
            for c in 0..n {
                lo[cur + c] = lo[p + c].min(slo[cur + c]);
                hi[cur + c] = hi[p + c].max(shi[cur + c]);
            }
        }
    }
}

/// Minimum and maximum of every `bh x bw` rectangle of a row-major
/// `rows x cols` pair of planes (`lo` for minima, `hi` for maxima; missing
/// samples hold `+inf` in `lo` and `-inf` in `hi`). Returns
/// `((rows - bh + 1) x (cols - bw + 1))` planes indexed by the rectangle's
/// top-left sample. Requires `1 <= bh <= rows`, `1 <= bw <= cols`.
pub(crate) fn rect_minmax(
    lo: &[f64],
    hi: &[f64],
    rows: usize,
    cols: usize,
    bh: usize,
    bw: usize,
) -> (Vec<f64>, Vec<f64>) {
    debug_assert!(bh >= 1 && bh <= rows && bw >= 1 && bw <= cols);
    let oc = cols - bw + 1;
    // horizontal pass, row by row
    let mut hlo = vec![0.0f64; rows * oc];
    let mut hhi = vec![0.0f64; rows * oc];
    let mut pre = vec![0.0f64; cols];
    let mut suf = vec![0.0f64; cols];
    let mut pre2 = vec![0.0f64; cols];
    let mut suf2 = vec![0.0f64; cols];
    for r in 0..rows {
        let (xl, xh) = (&lo[r * cols..(r + 1) * cols], &hi[r * cols..(r + 1) * cols]);
        let (ol, oh) = (
            &mut hlo[r * oc..(r + 1) * oc],
            &mut hhi[r * oc..(r + 1) * oc],
        );
        if bw == 1 {
            ol.copy_from_slice(xl);
            oh.copy_from_slice(xh);
            continue;
        }
        // prefix and suffix extrema within blocks of bw samples
        for b0 in (0..cols).step_by(bw) {
            let b1 = (b0 + bw).min(cols);
            pre[b0] = xl[b0];
            pre2[b0] = xh[b0];
            for c in b0 + 1..b1 {
                pre[c] = pre[c - 1].min(xl[c]);
                pre2[c] = pre2[c - 1].max(xh[c]);
            }
            suf[b1 - 1] = xl[b1 - 1];
            suf2[b1 - 1] = xh[b1 - 1];
            for c in (b0..b1 - 1).rev() {
                suf[c] = suf[c + 1].min(xl[c]);
                suf2[c] = suf2[c + 1].max(xh[c]);
            }
        }
        for c in 0..oc {
            ol[c] = suf[c].min(pre[c + bw - 1]);
            oh[c] = suf2[c].max(pre2[c + bw - 1]);
        }
    }
    if bh == 1 {
        return (hlo, hhi);
    }
    // vertical pass on whole rows (vectorises across columns)
    let orows = rows - bh + 1;
    let mut plo = vec![0.0f64; rows * oc];
    let mut phi = vec![0.0f64; rows * oc];
    let mut slo = vec![0.0f64; rows * oc];
    let mut shi = vec![0.0f64; rows * oc];
    let (h, acc) = ((&hlo[..], &hhi[..]), oc);
    for r in 0..rows {
        // prefix: a block of bh rows starts at every multiple of bh
        let from = (r % bh != 0).then(|| (r - 1) * oc);
        fold_row((&mut plo, &mut phi), h, r * oc, from, acc);
    }
    for r in (0..rows).rev() {
        // suffix: a block ends at bh - 1 modulo bh and at the last row
        let from = (r % bh != bh - 1 && r != rows - 1).then(|| (r + 1) * oc);
        fold_row((&mut slo, &mut shi), h, r * oc, from, acc);
    }
    let mut olo = vec![0.0f64; orows * oc];
    let mut ohi = vec![0.0f64; orows * oc];
    for r in 0..orows {
        let (a, b) = (r * oc, (r + bh - 1) * oc);
        for c in 0..oc {
            olo[a + c] = slo[a + c].min(plo[b + c]);
            ohi[a + c] = shi[a + c].max(phi[b + c]);
        }
    }
    (olo, ohi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_brute_force() {
        let (rows, cols) = (13usize, 11usize);
        // integers 0..999: every window sum is exact in either order
        let v: Vec<f64> = crate::testdata::uniform(rows * cols, 3)
            .into_iter()
            .map(|u| (u * 1000.0).floor())
            .collect();
        let lo: Vec<f64> = v
            .iter()
            .enumerate()
            .map(|(k, &x)| if k % 7 == 2 { f64::INFINITY } else { x })
            .collect();
        let hi: Vec<f64> = v
            .iter()
            .enumerate()
            .map(|(k, &x)| if k % 7 == 2 { f64::NEG_INFINITY } else { x })
            .collect();
        for (bh, bw) in [(1, 1), (2, 3), (4, 1), (1, 5), (5, 4), (13, 11), (3, 3)] {
            let (a, b) = rect_minmax(&lo, &hi, rows, cols, bh, bw);
            let oc = cols - bw + 1;
            for r in 0..=rows - bh {
                for c in 0..oc {
                    let (mut l, mut h) = (f64::INFINITY, f64::NEG_INFINITY);
                    for rr in r..r + bh {
                        for cc in c..c + bw {
                            l = l.min(lo[rr * cols + cc]);
                            h = h.max(hi[rr * cols + cc]);
                        }
                    }
                    assert_eq!(
                        (a[r * oc + c], b[r * oc + c]),
                        (l, h),
                        "{bh}x{bw} ({r},{c})"
                    );
                }
            }
        }
    }
}
