//! Stochastic plants on a DEM, merged into one scene mesh.
//!
//! Coordinates: cell `(row, col)` of the DEM has its centre at
//! `x = (col + 0.5) cell_size`, `y = (rows - row - 0.5) cell_size` (row 0 is
//! north) and height `dem[row, col]`. Plant `i` (for `i < n_plants`, with
//! `n_plants = round(density * area)` and `area` the extent of the cell
//! centres) stands at a uniform position drawn from a hash of `(seed, i)`,
//! at the bilinearly interpolated height, turned about the vertical by a
//! uniform angle and derived with its own seed `hash(seed, i)`. A plant whose
//! height is NaN (nodata) is left out. Everything depends on `(seed, i)`
//! only, so the scene is the same on any number of threads.
use super::derive::{hash3, unit3, LSystem};
use super::mesh::{build_mesh, Mesh};
use super::turtle::TurtleParams;
use crate::error::{CoreError, CoreResult};
use glam::{DQuat, DVec3};
use rayon::prelude::*;

/// Options of [`plants_on_terrain`].
#[derive(Debug, Clone)]
pub struct SceneParams {
    pub n: usize,
    pub turtle: TurtleParams,
    pub sides: usize,
    pub cell_size: f64,
    pub density: f64,
    pub seed: u64,
    pub scale: f64,
    pub max_plants: usize,
}

/// Bilinear height at fractional (row, col) in cell-centre units.
fn bilinear(dem: &[f64], rows: usize, cols: usize, r: f64, c: f64) -> f64 {
    let r0 = (r.floor() as usize).min(rows.saturating_sub(2));
    let c0 = (c.floor() as usize).min(cols.saturating_sub(2));
    let r1 = (r0 + 1).min(rows - 1);
    let c1 = (c0 + 1).min(cols - 1);
    let (tr, tc) = (
        (r - r0 as f64).clamp(0.0, 1.0),
        (c - c0 as f64).clamp(0.0, 1.0),
    );
    let z = |i: usize, j: usize| dem[i * cols + j];
    (1.0 - tr) * ((1.0 - tc) * z(r0, c0) + tc * z(r0, c1))
        + tr * ((1.0 - tc) * z(r1, c0) + tc * z(r1, c1))
}

/// Place plants of `lsystem` on the DEM (C order, `rows x cols`); returns
/// the scene mesh (instance ids per triangle) and the base point of every
/// plant placed.
pub fn plants_on_terrain(
    lsystem: &LSystem,
    dem: &[f64],
    rows: usize,
    cols: usize,
    p: &SceneParams,
) -> CoreResult<(Mesh, Vec<[f64; 3]>)> {
    if rows < 2 || cols < 2 || dem.len() != rows * cols {
        return Err(CoreError::invalid(
            "dem",
            "expected a 2D array of at least 2 x 2 cells",
        ));
    }
    if !(p.cell_size > 0.0 && p.cell_size.is_finite()) {
        return Err(CoreError::invalid(
            "cell_size",
            format!("must be positive and finite, got {}", p.cell_size),
        ));
    }
    if !(p.density >= 0.0 && p.density.is_finite()) {
        return Err(CoreError::invalid(
            "density",
            format!("must be >= 0 and finite, got {}", p.density),
        ));
    }
    if !(p.scale > 0.0 && p.scale.is_finite()) {
        return Err(CoreError::invalid(
            "scale",
            format!("must be positive and finite, got {}", p.scale),
        ));
    }
    if dem.iter().any(|v| v.is_infinite()) {
        return Err(CoreError::invalid(
            "dem",
            "heights must be finite or NaN (nodata)",
        ));
    }
    p.turtle.validate()?;
    let (w, h) = (
        (cols - 1) as f64 * p.cell_size,
        (rows - 1) as f64 * p.cell_size,
    );
    let n_plants = (p.density * w * h).round();
    if n_plants > p.max_plants as f64 {
        return Err(CoreError::invalid(
            "density",
            format!(
                "{n_plants} plants is more than max_plants={}; lower the density",
                p.max_plants
            ),
        ));
    }
    let n_plants = n_plants as usize;
    let placed: Vec<Option<(Mesh, [f64; 3])>> = (0..n_plants)
        .into_par_iter()
        .map(|i| {
            let i64_ = i as u64;
            let c = unit3(p.seed, i64_, 1) * (cols - 1) as f64;
            let r = unit3(p.seed, i64_, 2) * (rows - 1) as f64;
            let z = bilinear(dem, rows, cols, r, c);
            if z.is_nan() {
                return Ok(None);
            }
            let base = DVec3::new(
                (c + 0.5) * p.cell_size,
                (rows as f64 - r - 0.5) * p.cell_size,
                z,
            );
            let s = lsystem.derive_with_seed(p.n, hash3(p.seed, i64_, 3))?;
            let m = build_mesh(&s, &p.turtle, p.sides)?;
            let q = DQuat::from_rotation_z(std::f64::consts::TAU * unit3(p.seed, i64_, 4));
            let mut out = Mesh::default();
            out.append_transformed(&m, i as u32, |v| base + q * (v * p.scale), |n| q * n)?;
            Ok(Some((out, base.to_array())))
        })
        .collect::<CoreResult<Vec<_>>>()?;
    let mut scene = Mesh::default();
    let mut bases = Vec::new();
    for (m, b) in placed.into_iter().flatten() {
        let inst = m.instances.first().copied().unwrap_or(0);
        scene.append_transformed(&m, inst, |v| v, |n| n)?;
        bases.push(b);
    }
    Ok((scene, bases))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lsystem::derive::DEFAULT_MAX_LENGTH;
    use crate::parallel::run_in_pool;

    #[test]
    fn scene_is_seeded_and_sits_on_the_dem() {
        let rules = vec![
            "F -(1)-> F[+F]F".to_string(),
            "F -(1)-> F[-F]F".to_string(),
            "F -(1)-> FF".to_string(),
        ];
        let l = LSystem::new("F", &rules, "", 0, DEFAULT_MAX_LENGTH).unwrap();
        let (rows, cols) = (11, 21);
        // a plane z = 2 x + 3 y + 5 (bilinear interpolation is exact on it)
        let mut dem = Vec::new();
        for i in 0..rows {
            for j in 0..cols {
                let (x, y) = ((j as f64 + 0.5) * 2.0, ((rows - i) as f64 - 0.5) * 2.0);
                dem.push(2.0 * x + 3.0 * y + 5.0);
            }
        }
        let p = SceneParams {
            n: 3,
            turtle: TurtleParams::spatial(25.0, 1.0),
            sides: 4,
            cell_size: 2.0,
            density: 0.05,
            seed: 9,
            scale: 0.5,
            max_plants: 10_000,
        };
        let (a, ba) = run_in_pool(Some(1), || plants_on_terrain(&l, &dem, rows, cols, &p)).unwrap();
        let (b, bb) = run_in_pool(Some(3), || plants_on_terrain(&l, &dem, rows, cols, &p)).unwrap();
        assert_eq!(a, b);
        assert_eq!(ba, bb);
        // 0.05 * (20 * 2) * (10 * 2) = 40 plants
        assert_eq!(ba.len(), 40);
        for q in &ba {
            assert!((q[2] - (2.0 * q[0] + 3.0 * q[1] + 5.0)).abs() < 1e-9);
            assert!(q[0] >= 1.0 && q[0] <= 41.0 && q[1] >= 1.0 && q[1] <= 21.0);
        }
        assert_eq!(*a.instances.iter().max().unwrap(), 39);
        // plants differ (stochastic rules, own seeds)
        let tri_of = |k: u32| a.instances.iter().filter(|&&i| i == k).count();
        assert!(
            (0..40)
                .map(tri_of)
                .collect::<std::collections::HashSet<_>>()
                .len()
                > 1
        );
        // nodata holes drop plants; errors name the parameter
        let mut holes = dem.clone();
        for v in holes.iter_mut().take(cols * 6) {
            *v = f64::NAN;
        }
        let (_, bh) = plants_on_terrain(&l, &holes, rows, cols, &p).unwrap();
        assert!(bh.len() < 40 && !bh.is_empty());
        let bad = SceneParams {
            density: -1.0,
            ..p.clone()
        };
        assert!(plants_on_terrain(&l, &dem, rows, cols, &bad)
            .unwrap_err()
            .to_string()
            .starts_with("density:"));
        let bad = SceneParams {
            density: 100.0,
            ..p
        };
        assert!(plants_on_terrain(&l, &dem, rows, cols, &bad)
            .unwrap_err()
            .to_string()
            .starts_with("density:"));
    }
}
