//! Moving-window gliding-box lacunarity (Allain and Cloitre 1991).
//!
//! For box side `r` the boxes glide over every position *inside* the window
//! (the window clipped to the image at the edges); with box masses `M` (sums
//! of the values; boxes touching NaN are left out) the window's value is
//! `Lambda(r) = E[M^2] / E[M]^2`. Box masses, their squares and their
//! validity are summed over windows with summed-area tables per band, so the
//! cost per pixel does not grow with the window.
use super::driver::Grid;
use super::sat::{rect, sat};
use crate::error::{CoreError, CoreResult};
use crate::sample::Sample;

/// Lacunarity maps, layout `[size][row][col]` (NaN where the window holds no
/// complete valid box or fewer valid pixels than `min_valid * w * w`).
pub fn lacunarity_transform<T: Sample>(
    z: &[T],
    rows: usize,
    cols: usize,
    window: usize,
    box_sizes: &[usize],
    min_valid: f64,
) -> CoreResult<Vec<f32>> {
    let w = window;
    let grid = Grid::new(z.len(), rows, cols, w, min_valid, 1)?;
    let min_pixels = grid.min_pixels;
    if box_sizes.is_empty() || box_sizes.iter().any(|&r| r == 0 || r > w) {
        return Err(CoreError::invalid(
            "box_sizes",
            format!("box sides must be in [1, {w}], got {box_sizes:?}"),
        ));
    }
    // each band writes its rows of every size plane
    let planes = grid.drive(&vec![true; box_sizes.len()], |_: &mut (), band, outs| {
        let (o0, o1, i0, i1) = (band.g0, band.g1, band.i0, band.i1);
        let nr = i1 - i0;
        let sw = cols + 1;
        let zz: Vec<f64> = z[i0 * cols..i1 * cols]
            .iter()
            .map(|&v| {
                let v = v.to_f64();
                if v.is_nan() {
                    0.0
                } else {
                    v
                }
            })
            .collect();
        let nan: Vec<f64> = z[i0 * cols..i1 * cols]
            .iter()
            .map(|&v| v.to_f64().is_nan() as u8 as f64)
            .collect();
        let (zs, ns) = (sat(&zz, nr, cols), sat(&nan, nr, cols));
        for (&r, plane_out) in box_sizes.iter().zip(outs.iter_mut()) {
            if nr < r || cols < r {
                continue;
            }
            // box anchors (top-left) a in [0, nr - r], b in [0, cols - r]
            let (na, nb) = (nr - r + 1, cols - r + 1);
            let mut m1 = vec![0.0f64; na * nb];
            let mut m2 = vec![0.0f64; na * nb];
            let mut vv = vec![0.0f64; na * nb];
            for a in 0..na {
                for b in 0..nb {
                    if rect(&ns, sw, a, a + r, b, b + r) == 0.0 {
                        let m = rect(&zs, sw, a, a + r, b, b + r);
                        m1[a * nb + b] = m;
                        m2[a * nb + b] = m * m;
                        vv[a * nb + b] = 1.0;
                    }
                }
            }
            let (s1, s2, sv) = (sat(&m1, na, nb), sat(&m2, na, nb), sat(&vv, na, nb));
            let bw = nb + 1;
            for i in o0..o1 {
                let (r0, r1) = grid.win_rows(band, i);
                if r1 < r0 + r {
                    continue;
                }
                for j in 0..cols {
                    let (c0, c1) = grid.win_cols(j);
                    if c1 < c0 + r {
                        continue;
                    }
                    if rect(&ns, sw, r0, r1, c0, c1)
                        > (r1 - r0) as f64 * (c1 - c0) as f64 - min_pixels
                    {
                        continue; // too few valid pixels
                    }
                    let (ar1, bc1) = (r1 - r + 1, c1 - r + 1);
                    let n = rect(&sv, bw, r0, ar1, c0, bc1);
                    if n < 0.5 {
                        continue;
                    }
                    let mean = rect(&s1, bw, r0, ar1, c0, bc1) / n;
                    let sq = rect(&s2, bw, r0, ar1, c0, bc1) / n;
                    if mean > 0.0 {
                        plane_out[(i - o0) * cols + j] = (sq / (mean * mean)) as f32;
                    }
                }
            }
        }
    })?;
    Ok(planes.concat())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_image_has_lacunarity_one() {
        let z = vec![2.0f64; 40 * 30];
        let l = lacunarity_transform(&z, 40, 30, 9, &[1, 2, 4], 0.5).unwrap();
        for s in 0..3 {
            for i in 10..30 {
                for j in 10..20 {
                    assert!((l[s * 1200 + i * 30 + j] - 1.0).abs() < 1e-6);
                }
            }
        }
    }
}
