//! Delaunay and constrained Delaunay triangulation of scattered 2D points.
//!
//! The points are bulk-loaded into spade (exact predicates, so degenerate
//! inputs such as regular grids and cocircular sets triangulate without
//! failure; the choice among equally valid diagonals is spade's). Exact
//! duplicates are merged: the triangles index the first occurrence.
use super::{indexed_points, insertion_error, Indexed};
use crate::error::{CoreError, CoreResult};
use spade::handles::FixedVertexHandle;
use spade::{
    ConstrainedDelaunayTriangulation, DelaunayTriangulation, PositionInTriangulation, Triangulation,
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

/// Make every vertex carry the smallest input index among its exact
/// duplicates (spade keeps one copy of duplicates, not necessarily the
/// first); return the vertex handle of every input point.
fn merge_duplicates<T>(tri: &mut T, vertices: &[Indexed]) -> CoreResult<Vec<FixedVertexHandle>>
where
    T: Triangulation<Vertex = Indexed>,
{
    let n = vertices.len();
    let mut handle: Vec<Option<FixedVertexHandle>> = vec![None; n];
    for v in tri.vertices() {
        handle[v.data().idx] = Some(v.fix());
    }
    if tri.num_vertices() < n {
        for (i, v) in vertices.iter().enumerate() {
            if handle[i].is_some() {
                continue;
            }
            match tri.locate(v.pos) {
                PositionInTriangulation::OnVertex(h) => {
                    handle[i] = Some(h);
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

fn triangles_of<T: Triangulation<Vertex = Indexed>>(tri: &T) -> Vec<[i64; 3]> {
    tri.inner_faces()
        .map(|f| {
            let [a, b, c] = f.vertices();
            [
                a.data().idx as i64,
                b.data().idx as i64,
                c.data().idx as i64,
            ]
        })
        .collect()
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
    match constraints {
        None | Some([]) => {
            let mut tri: DelaunayTriangulation<Indexed> =
                DelaunayTriangulation::bulk_load(vertices.clone())
                    .map_err(|e| insertion_error("points", e))?;
            merge_duplicates(&mut tri, &vertices)?;
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
                ConstrainedDelaunayTriangulation::bulk_load(vertices.clone())
                    .map_err(|e| insertion_error("points", e))?;
            let handle = merge_duplicates(&mut cdt, &vertices)?;
            check_size(&cdt)?;
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
