//! Delaunay and constrained Delaunay triangulation of scattered 2D points.
//!
//! The points are bulk-loaded into spade (exact predicates, so degenerate
//! inputs such as regular grids and cocircular sets triangulate without
//! failure; the choice among equally valid diagonals is spade's). Exact
//! duplicates are merged: the triangles index the first occurrence.
use super::{indexed_points, insertion_error, Indexed};
use crate::error::{CoreError, CoreResult};
use rayon::prelude::*;
use spade::handles::{FixedFaceHandle, FixedVertexHandle, InnerTag};
use spade::{
    ConstrainedDelaunayTriangulation, DelaunayTriangulation, Point2, PositionInTriangulation,
    Triangulation,
};

/// Point `i` of the caller's array as `(x, y)`.
pub trait PointSource: Sync {
    fn len(&self) -> usize;
    fn xy(&self, i: usize) -> (f64, f64);
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl PointSource for ndarray::ArrayView2<'_, f64> {
    fn len(&self) -> usize {
        self.nrows()
    }
    fn xy(&self, i: usize) -> (f64, f64) {
        (self[[i, 0]], self[[i, 1]])
    }
}

/// Put `vertices` in the order spade's circle-sweep bulk loading inserts
/// them (distance from the mean position, farthest first, then `x`, then
/// `y`), with the input index as the final key so the order is total.
///
/// spade sorts its input by the same key with `sort_unstable`, which returns
/// at once on a sorted slice: sorting here in parallel (rayon, in the
/// current pool) moves that sort off the sequential path. The mean is
/// summed in input order exactly as spade does, so the keys are
/// bit-identical; were they not, spade would only sort again (same result).
/// The result does not depend on the number of threads (a total order).
pub(crate) fn sweep_order(vertices: &mut [Indexed]) {
    if vertices.is_empty() {
        return;
    }
    let mut sum = Point2::new(0.0f64, 0.0f64);
    for v in vertices.iter() {
        sum = Point2::new(sum.x + v.pos.x, sum.y + v.pos.y);
    }
    let k = 1.0 / vertices.len() as f64;
    let center = Point2::new(sum.x * k, sum.y * k);
    vertices.par_sort_unstable_by(|a, b| {
        let (da, db) = (center.distance_2(a.pos), center.distance_2(b.pos));
        db.total_cmp(&da)
            .then(a.pos.x.total_cmp(&b.pos.x))
            .then(a.pos.y.total_cmp(&b.pos.y))
            .then(a.idx.cmp(&b.idx))
    });
}

/// Bulk-load `vertices` (in [`sweep_order`] first) and make every vertex
/// carry the smallest input index among its exact duplicates (spade keeps
/// one copy of duplicates, not necessarily the first). `xy(i)` is input
/// point `i`, used to find the kept copy of a dropped duplicate.
pub(crate) fn bulk_load_merged<T>(
    mut vertices: Vec<Indexed>,
    xy: impl Fn(usize) -> Point2<f64>,
) -> CoreResult<T>
where
    T: Triangulation<Vertex = Indexed>,
{
    let n = vertices.len();
    sweep_order(&mut vertices);
    let mut tri = T::bulk_load(vertices).map_err(|e| insertion_error("points", e))?;
    if tri.num_vertices() < n {
        let mut kept = vec![false; n];
        for v in tri.vertices() {
            kept[v.data().idx] = true;
        }
        for (i, &k) in kept.iter().enumerate() {
            if k {
                continue;
            }
            match tri.locate(xy(i)) {
                PositionInTriangulation::OnVertex(h) => {
                    let d = tri.vertex_data_mut(h);
                    d.idx = d.idx.min(i);
                }
                _ => {
                    return Err(CoreError::Internal(format!(
                        "point {i} was dropped by the triangulation but is not a duplicate"
                    )))
                }
            }
        }
    }
    Ok(tri)
}

/// The vertex handle of every input point (duplicates share one), for a
/// triangulation made by [`bulk_load_merged`].
fn input_handles<T>(
    tri: &T,
    n: usize,
    xy: impl Fn(usize) -> Point2<f64>,
) -> CoreResult<Vec<FixedVertexHandle>>
where
    T: Triangulation<Vertex = Indexed>,
{
    let mut handle: Vec<Option<FixedVertexHandle>> = vec![None; n];
    for v in tri.vertices() {
        handle[v.data().idx] = Some(v.fix());
    }
    for (i, h) in handle.iter_mut().enumerate() {
        if h.is_none() {
            if let PositionInTriangulation::OnVertex(v) = tri.locate(xy(i)) {
                *h = Some(v);
            }
        }
    }
    handle
        .into_iter()
        .enumerate()
        .map(|(i, h)| h.ok_or_else(|| CoreError::Internal(format!("point {i} has no vertex"))))
        .collect()
}

fn check_size<T: Triangulation<Vertex = Indexed>>(tri: &T) -> CoreResult<()> {
    if tri.num_vertices() < 3 {
        return Err(CoreError::invalid(
            "points",
            format!(
                "need at least 3 distinct points, got {}",
                tri.num_vertices()
            ),
        ));
    }
    if tri.num_inner_faces() == 0 {
        return Err(CoreError::invalid(
            "points",
            "all points are collinear: there is no triangle",
        ));
    }
    Ok(())
}

/// The inner faces as input indices, in spade's face order; faces are read
/// in parallel (the triangulation is only read), the order is fixed.
fn triangles_of<T: Triangulation<Vertex = Indexed> + Sync>(tri: &T) -> Vec<[i64; 3]> {
    let faces: Vec<FixedFaceHandle<InnerTag>> = tri.fixed_inner_faces().collect();
    faces
        .par_iter()
        .with_min_len(1 << 14)
        .map(|&f| {
            let [a, b, c] = tri.face(f).vertices();
            [
                a.data().idx as i64,
                b.data().idx as i64,
                c.data().idx as i64,
            ]
        })
        .collect()
}

/// Sorted distinct values of `v` (by `total_cmp`; no NaN here).
fn distinct(mut v: Vec<f64>) -> Vec<f64> {
    v.par_sort_unstable_by(|a, b| a.total_cmp(b));
    v.dedup();
    v
}

/// The triangles of a complete rectilinear lattice (see the module
/// documentation), or `None` when the distinct points of `vertices` are not
/// all of `xs x ys` for some `xs`, `ys` with at least two values each.
///
/// Counter-clockwise, cells in row-major order (y, then x ascending), each
/// cell as `(a, b, c)`, `(a, c, d)` with `a, b, c, d` its lower-left,
/// lower-right, upper-right, upper-left corners; a corner is the smallest
/// input index among its exact duplicates. Cheap to reject: a lattice of
/// `m <= n` distinct points has at most `sqrt(m)` values along one axis,
/// so any `2 floor(sqrt(n)) + 2` of its points repeat a value on that
/// axis; when the first ones do not, the input is no lattice.
pub(crate) fn lattice_triangles(vertices: &[Indexed]) -> Option<Vec<[i64; 3]>> {
    let n = vertices.len();
    if n < 4 {
        return None;
    }
    let m = (2 * (n as f64).sqrt() as usize + 2).min(n);
    let head = &vertices[..m];
    let nx_head = distinct(head.iter().map(|v| v.pos.x).collect()).len();
    let ny_head = distinct(head.iter().map(|v| v.pos.y).collect()).len();
    if nx_head == m && ny_head == m {
        return None;
    }
    let xs = distinct(vertices.par_iter().map(|v| v.pos.x).collect());
    let nx = xs.len();
    if nx < 2 || nx > n / 2 {
        return None;
    }
    let ys = distinct(vertices.par_iter().map(|v| v.pos.y).collect());
    let ny = ys.len();
    if ny < 2 || nx.checked_mul(ny)? > n {
        return None;
    }
    let find = |s: &[f64], v: f64| s.binary_search_by(|a| a.total_cmp(&v)).ok();
    // The cell of every input point, then the smallest index per node.
    let node: Vec<usize> = vertices
        .par_iter()
        .map(|v| match (find(&xs, v.pos.x), find(&ys, v.pos.y)) {
            (Some(i), Some(j)) => j * nx + i,
            _ => usize::MAX,
        })
        .collect();
    let mut first = vec![usize::MAX; nx * ny];
    for (v, &k) in vertices.iter().zip(&node) {
        let f = first.get_mut(k)?;
        *f = (*f).min(v.idx);
    }
    if first.contains(&usize::MAX) {
        return None;
    }
    let cells = (nx - 1) * (ny - 1);
    let mut out = vec![[0i64; 3]; 2 * cells];
    out.par_chunks_mut(2 * (nx - 1))
        .enumerate()
        .for_each(|(j, row)| {
            for i in 0..nx - 1 {
                let a = first[j * nx + i] as i64;
                let b = first[j * nx + i + 1] as i64;
                let c = first[(j + 1) * nx + i + 1] as i64;
                let d = first[(j + 1) * nx + i] as i64;
                row[2 * i] = [a, b, c];
                row[2 * i + 1] = [a, c, d];
            }
        });
    Some(out)
}

/// Delaunay triangulation of `points`, constrained by the point-index pairs
/// `constraints` when given (a constrained Delaunay triangulation: every
/// constraint segment is a union of triangle edges; a constraint through
/// other input points is split at them).
///
/// Returns triangles as input-point indices, counter-clockwise (positive
/// signed area). Errors: fewer than 3 distinct points, all points
/// collinear, NaN/inf coordinates, a constraint index out of range, a
/// constraint joining a point to itself (or to its duplicate), constraints
/// that cross each other.
pub fn delaunay<P: PointSource>(
    points: &P,
    constraints: Option<&[[i64; 2]]>,
) -> CoreResult<Vec<[i64; 3]>> {
    let n = points.len();
    let vertices = indexed_points("points", n, |i| points.xy(i))?;
    let xy = |i: usize| {
        let (x, y) = points.xy(i);
        Point2::new(x + 0.0, y + 0.0)
    };
    match constraints {
        None | Some([]) => {
            if let Some(t) = lattice_triangles(&vertices) {
                return Ok(t);
            }
            let tri: DelaunayTriangulation<Indexed> = bulk_load_merged(vertices, xy)?;
            check_size(&tri)?;
            Ok(triangles_of(&tri))
        }
        Some(edges) => {
            for (k, &[a, b]) in edges.iter().enumerate() {
                for v in [a, b] {
                    if v < 0 || v as u64 >= n as u64 {
                        return Err(CoreError::invalid(
                            "constraints",
                            format!("row {k} ({a}, {b}) has an index outside [0, {n})"),
                        ));
                    }
                }
            }
            let mut cdt: ConstrainedDelaunayTriangulation<Indexed> =
                bulk_load_merged(vertices, xy)?;
            check_size(&cdt)?;
            let handle = input_handles(&cdt, n, xy)?;
            for (k, &[a, b]) in edges.iter().enumerate() {
                let (ha, hb) = (handle[a as usize], handle[b as usize]);
                if ha == hb {
                    return Err(CoreError::invalid(
                        "constraints",
                        format!("row {k} ({a}, {b}) joins a point to itself"),
                    ));
                }
                if !cdt.can_add_constraint(ha, hb) {
                    return Err(CoreError::invalid(
                        "constraints",
                        format!("row {k} ({a}, {b}) crosses an earlier constraint"),
                    ));
                }
                cdt.add_constraint(ha, hb);
            }
            Ok(triangles_of(&cdt))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::Array2;

    fn orient(p: &Array2<f64>, t: [i64; 3]) -> f64 {
        let [a, b, c] = t.map(|i| i as usize);
        (p[[b, 0]] - p[[a, 0]]) * (p[[c, 1]] - p[[a, 1]])
            - (p[[b, 1]] - p[[a, 1]]) * (p[[c, 0]] - p[[a, 0]])
    }

    fn lattice(xs: &[f64], ys: &[f64]) -> Vec<Indexed> {
        let mut v = Vec::new();
        for &y in ys {
            for &x in xs {
                let idx = v.len();
                v.push(Indexed {
                    pos: Point2::new(x, y),
                    idx,
                });
            }
        }
        v
    }

    #[test]
    fn lattice_fast_path_only_for_complete_lattices() {
        let xs = [0.0, 0.5, 2.0, 2.25, 7.0];
        let ys = [-3.0, -1.0, 10.0];
        let mut v = lattice(&xs, &ys);
        // reverse the order and repeat two points with higher indices
        v.reverse();
        let n = v.len();
        v.push(Indexed {
            pos: Point2::new(2.0, 10.0),
            idx: n,
        });
        v.push(Indexed {
            pos: Point2::new(0.0, -3.0),
            idx: n + 1,
        });
        let t = lattice_triangles(&v).expect("a complete lattice");
        assert_eq!(t.len(), 2 * 4 * 2);
        let pos = |i: i64| v.iter().find(|q| q.idx == i as usize).unwrap().pos;
        for tr in &t {
            assert!(tr.iter().all(|&i| (i as usize) < n));
            let [a, b, c] = tr.map(pos);
            assert!((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x) > 0.0);
        }
        // one node missing, or one point off the lattice: spade's path
        let mut missing = lattice(&xs, &ys);
        missing.remove(7);
        assert!(lattice_triangles(&missing).is_none());
        let mut off = lattice(&xs, &ys);
        off.push(Indexed {
            pos: Point2::new(1.0, 1.0),
            idx: 15,
        });
        assert!(lattice_triangles(&off).is_none());
        // a single row or column is no lattice (collinear)
        assert!(lattice_triangles(&lattice(&xs, &[1.0])).is_none());
        assert!(lattice_triangles(&lattice(&[1.0], &ys)).is_none());
    }

    #[test]
    fn square_with_duplicate_keeps_first() {
        let p =
            Array2::from_shape_vec((5, 2), vec![0., 0., 1., 0., 1., 1., 0., 1., 1., 0.]).unwrap();
        let t = delaunay(&p.view(), None).unwrap();
        assert_eq!(t.len(), 2);
        for &tr in &t {
            assert!(orient(&p, tr) > 0.0);
            assert!(!tr.contains(&4));
        }
    }

    #[test]
    fn collinear_and_crossing_are_errors() {
        let p = Array2::from_shape_vec((3, 2), vec![0., 0., 1., 1., 2., 2.]).unwrap();
        assert!(delaunay(&p.view(), None).is_err());
        let q = Array2::from_shape_vec((4, 2), vec![0., 0., 1., 0., 1., 1., 0., 1.]).unwrap();
        let e = delaunay(&q.view(), Some(&[[0, 2], [1, 3]])).unwrap_err();
        assert!(e.to_string().starts_with("constraints: row 1"));
        let t = delaunay(&q.view(), Some(&[[1, 3]])).unwrap();
        assert!(t.iter().all(|tr| tr.contains(&1) && tr.contains(&3)));
    }
}
