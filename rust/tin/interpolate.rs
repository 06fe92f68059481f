//! Gridding of scattered values through a Delaunay triangulation: natural
//! neighbour (Sibson 1981; C0, and C1 with estimated gradients), linear
//! (barycentric in the containing triangle) and nearest neighbour. Grid
//! nodes outside the convex hull of the points are NaN for every method.
use super::delaunay::{bulk_load_merged, PointSource};
use super::{indexed_points, Indexed};
use crate::error::{CoreError, CoreResult};
use rayon::prelude::*;
use spade::handles::FixedVertexHandle;
use spade::{
    DelaunayTriangulation, FloatTriangulation, HierarchyHintGenerator, Point2,
    PositionInTriangulation, Triangulation,
};

/// Interpolation method of [`grid_from_points`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Sibson's natural-neighbour interpolation (C0 at the data points, C1 elsewhere).
    Natural,
    /// Sibson's C1 natural-neighbour interpolation with gradients estimated
    /// from the area-weighted normals of the triangles around each point.
    NaturalC1,
    /// Barycentric interpolation in the Delaunay triangle (piecewise linear).
    Linear,
    /// Value of the nearest point.
    Nearest,
}

impl Method {
    /// Parse `"natural"`, `"natural_c1"`, `"linear"` or `"nearest"`.
    pub fn parse(s: &str) -> CoreResult<Method> {
        match s {
            "natural" => Ok(Method::Natural),
            "natural_c1" => Ok(Method::NaturalC1),
            "linear" => Ok(Method::Linear),
            "nearest" => Ok(Method::Nearest),
            _ => Err(CoreError::invalid(
                "method",
                format!("must be 'natural', 'natural_c1', 'linear' or 'nearest', got {s:?}"),
            )),
        }
    }
}

type Tri = DelaunayTriangulation<Indexed, (), (), (), HierarchyHintGenerator<f64>>;

/// Interpolate `values` at the points onto the `rows x cols` grid whose node
/// `(r, c)` sits at `x = t[0] + t[1] * c + t[2] * r`, `y = t[3] + t[4] * c
/// + t[5] * r` (a GDAL geotransform applied to node coordinates).
///
/// Exact duplicate points take the value of their first occurrence. Runs
/// rows in parallel in the current rayon pool; every node is computed on
/// its own, so the result does not depend on the number of threads.
pub fn grid_from_points<P: PointSource>(
    points: &P,
    values: &[f64],
    rows: usize,
    cols: usize,
    t: [f64; 6],
    method: Method,
) -> CoreResult<Vec<f64>> {
    let n = points.len();
    if values.len() != n {
        return Err(CoreError::invalid(
            "values",
            format!("has {} entries for {n} points", values.len()),
        ));
    }
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(CoreError::invalid(
            "values",
            format!("entry {i} is NaN or infinite ({})", values[i]),
        ));
    }
    let cells = rows
        .checked_mul(cols)
        .filter(|&c| c <= (1usize << 40))
        .ok_or_else(|| CoreError::invalid("shape", format!("{rows} x {cols} is too large")))?;
    let vertices = indexed_points("points", n, |i| points.xy(i))?;
    // Duplicates: the kept vertex takes the first occurrence's index.
    let tri: Tri = bulk_load_merged(vertices, |i| {
        let (x, y) = points.xy(i);
        Point2::new(x + 0.0, y + 0.0)
    })?;
    if tri.num_vertices() < 3 || tri.num_inner_faces() == 0 {
        return Err(CoreError::invalid(
            "points",
            "need at least 3 distinct points that are not all collinear",
        ));
    }
    let mut out = Vec::new();
    out.try_reserve_exact(cells).map_err(|_| {
        CoreError::invalid("shape", format!("cannot allocate {rows} x {cols} values"))
    })?;
    out.resize(cells, f64::NAN);
    let value = |v: spade::handles::VertexHandle<Indexed, (), (), ()>| values[v.data().idx];
    // C1: per-vertex values and gradients (spade's area-weighted normals),
    // by vertex index; each gradient is computed on its own, in parallel.
    let (vals, grads): (Vec<f64>, Vec<[f64; 2]>) = if method == Method::NaturalC1 {
        let vals = tri.vertices().map(value).collect();
        let grads = (0..tri.num_vertices())
            .into_par_iter()
            .with_min_len(1024)
            .map_init(
                || tri.natural_neighbor(),
                |nn, i| nn.estimate_gradient(tri.vertex(FixedVertexHandle::from_index(i)), value),
            )
            .collect();
        (vals, grads)
    } else {
        (Vec::new(), Vec::new())
    };
    out.par_chunks_mut(cols.max(1))
        .enumerate()
        .for_each(|(r, row)| {
            let nn = tri.natural_neighbor();
            let bary = tri.barycentric();
            let mut weights = Vec::new();
            for (c, o) in row.iter_mut().enumerate() {
                let (cf, rf) = (c as f64, r as f64);
                let p = Point2::new(t[0] + t[1] * cf + t[2] * rf, t[3] + t[4] * cf + t[5] * rf);
                let v = match method {
                    Method::Natural => nn.interpolate(value, p),
                    Method::NaturalC1 => {
                        nn.get_weights(p, &mut weights);
                        sibson_c1(&tri, &weights, &vals, &grads, p)
                    }
                    Method::Linear => bary.interpolate(value, p),
                    Method::Nearest => match tri.locate(p) {
                        PositionInTriangulation::OutsideOfConvexHull(_)
                        | PositionInTriangulation::NoTriangulation => None,
                        _ => tri.nearest_neighbor(p).map(value),
                    },
                };
                *o = v.unwrap_or(f64::NAN);
            }
        });
    Ok(out)
}

/// Sibson's C1 natural-neighbour blend at `p` from the natural-neighbour
/// weights `w` (Sibson 1981): with `r_i = |p - x_i|`, `zeta_i = f_i + grad_i
/// . (p - x_i)`, `alpha = sum(w_i / r_i^2 * r_i^2) / sum(w_i / r_i^2)`,
/// `beta = sum(w_i r_i^2)`, the value is `(alpha sum(w_i f_i) + beta
/// sum(w_i / r_i^2 zeta_i) / sum(w_i / r_i^2)) / (alpha + beta)`.
///
/// The same operations as spade's `interpolate_gradient` with flatness 1
/// (whose `(r_i^2)^flatness` is then `r_i^2` itself), without its `powf`
/// per neighbour. `vals` and `grads` are indexed by vertex.
fn sibson_c1(
    tri: &Tri,
    w: &[(FixedVertexHandle, f64)],
    vals: &[f64],
    grads: &[[f64; 2]],
    p: Point2<f64>,
) -> Option<f64> {
    if w.is_empty() {
        return None;
    }
    let (mut sum_c0, mut sum_c1, mut sum_c1_weights, mut alpha, mut beta) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for &(h, weight) in w {
        let q = tri.vertex(h).position();
        let (dx, dy) = (p.x - q.x, p.y - q.y);
        let r2 = dx * dx + dy * dy;
        let f = vals[h.index()];
        if r2 == 0.0 {
            return Some(f);
        }
        let c1_weight = weight / r2;
        let g = grads[h.index()];
        let zeta = f + (dx * g[0] + dy * g[1]);
        alpha += c1_weight * r2;
        beta += weight * r2;
        sum_c1_weights += c1_weight;
        sum_c1 += zeta * c1_weight;
        sum_c0 += f * weight;
    }
    alpha /= sum_c1_weights;
    sum_c1 /= sum_c1_weights;
    Some((alpha * sum_c0 + beta * sum_c1) / (alpha + beta))
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::Array2;

    #[test]
    fn linear_function_is_reproduced() {
        let mut pts = vec![0., 0., 10., 0., 10., 10., 0., 10.];
        pts.extend(crate::testdata::uniform(400, 7).iter().map(|u| 10.0 * u));
        let p = Array2::from_shape_vec((pts.len() / 2, 2), pts).unwrap();
        let vals: Vec<f64> = p
            .rows()
            .into_iter()
            .map(|r| 1.0 + 2.0 * r[0] - 3.0 * r[1])
            .collect();
        for m in [Method::Natural, Method::Linear, Method::NaturalC1] {
            let g =
                grid_from_points(&p.view(), &vals, 11, 11, [0., 1., 0., 0., 0., 1.], m).unwrap();
            for r in 0..11 {
                for c in 0..11 {
                    let want = 1.0 + 2.0 * c as f64 - 3.0 * r as f64;
                    assert!((g[r * 11 + c] - want).abs() < 1e-9, "{m:?} {r} {c}");
                }
            }
        }
        let g = grid_from_points(
            &p.view(),
            &vals,
            1,
            1,
            [20., 1., 0., 0., 0., 1.],
            Method::Nearest,
        )
        .unwrap();
        assert!(g[0].is_nan());
    }
}
