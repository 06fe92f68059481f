//! Mesh scenes against closed forms and against the heightfield caster.
use super::direction;
use super::heightfield::{Heightfield, Split};
use super::integrator::Scene;
use super::material::{self, Bsdf};
use super::mesh_tracer::MeshTracer;
use super::tracer::Tracer;
use crate::geometry::Mesh;
use crate::parallel::run_in_pool;
use crate::rng::StreamKey;
use glam::DVec3;

fn dir(az: f64, zen: f64) -> DVec3 {
    direction((az, zen), "sun").unwrap()
}

fn lam(rho: f64) -> Box<dyn Bsdf> {
    material::from_name("lambertian", &[rho]).unwrap()
}

/// A periodic rough tile as in `tests.rs`, heights rounded to f32 so that
/// the heightfield and the (f32) mesh hold the same surface.
fn rough(n: usize, amp: f64, seed: u64) -> Vec<f64> {
    let k = StreamKey::new(seed, 0);
    let mut z = vec![0.0; n * n];
    let mut idx = 0;
    for kx in -3i64..=3 {
        for ky in -3i64..=3 {
            if kx == 0 && ky == 0 {
                continue;
            }
            let a = amp * (k.uniform(idx) - 0.5) / ((kx * kx + ky * ky) as f64).sqrt();
            let ph = 2.0 * std::f64::consts::PI * k.uniform(idx + 1);
            idx += 2;
            for r in 0..n {
                for c in 0..n {
                    let arg = 2.0 * std::f64::consts::PI * (kx * c as i64 + ky * r as i64) as f64
                        / n as f64;
                    z[r * n + c] += a * (arg + ph).cos();
                }
            }
        }
    }
    z.iter().map(|&v| v as f32 as f64).collect()
}

/// The mesh of a periodic `rows x cols` tile with 1 m cells in the
/// heightfield's frame (vertex `(r, c)` at `(c, -r, z)`), facets in the
/// heightfield's order (cell by cell, NE-SW split), counter-clockwise from
/// above.
fn tile_mesh(z: &[f64], rows: usize, cols: usize) -> Mesh {
    let id = |r: usize, c: usize| (r * (cols + 1) + c) as u32;
    let mut vertices = Vec::new();
    for r in 0..=rows {
        for c in 0..=cols {
            vertices.push([
                c as f32,
                -(r as f32),
                z[(r % rows) * cols + c % cols] as f32,
            ]);
        }
    }
    let mut faces = Vec::new();
    for r in 0..rows {
        for c in 0..cols {
            let (nw, ne, sw, se) = (id(r, c), id(r, c + 1), id(r + 1, c), id(r + 1, c + 1));
            faces.push([nw, sw, ne]);
            faces.push([ne, sw, se]);
        }
    }
    Mesh {
        vertices,
        faces,
        ..Mesh::default()
    }
}

fn tile_extent(rows: usize, cols: usize) -> Option<[f64; 4]> {
    Some([0.0, -(rows as f64), cols as f64, rows as f64])
}

#[test]
fn flat_plane_mesh_gives_rho_exactly() {
    let z = vec![0.25; 16];
    let mesh = tile_mesh(&z, 4, 4);
    for periodic in [true, false] {
        let tr = MeshTracer::new(&mesh, periodic, tile_extent(4, 4)).unwrap();
        let s = Scene::new(tr, lam(0.37));
        for (sun, view) in [((0.0, 0.0), (0.0, 0.0)), ((30.0, 60.0), (200.0, 45.0))] {
            let e = s
                .brf(dir(sun.0, sun.1), dir(view.0, view.1), 2000, 5, 1)
                .unwrap();
            if periodic {
                assert!((e.value - 0.37).abs() < 1e-6 && e.se < 1e-6, "{e:?}");
            }
            let a = s.albedo(dir(sun.0, sun.1), 2000, 5, 1).unwrap();
            if periodic {
                assert!((a.value - 0.37).abs() < 1e-6 && a.se < 1e-6, "{a:?}");
            }
        }
        // nadir sun and view: exact even for the finite patch
        let e = s.brf(DVec3::Z, DVec3::Z, 500, 5, 1).unwrap();
        assert!((e.value - 0.37).abs() < 1e-6, "{e:?}");
    }
}

#[test]
fn mesh_and_heightfield_hit_the_same_facets() {
    let n = 12;
    let z = rough(n, 1.5, 3);
    let hf = Heightfield::new(&z, n, n, (1.0, 1.0), true, Split::NeSw).unwrap();
    let tr = MeshTracer::new(&tile_mesh(&z, n, n), true, tile_extent(n, n)).unwrap();
    assert_eq!(hf.facet_count(), tr.facet_count());
    for ((a1, n1), (a2, n2)) in hf.facets().iter().zip(tr.facets()) {
        assert!((a1 - a2).abs() < 1e-9 && (*n1 - n2).length() < 1e-9);
    }
    let key = StreamKey::new(9, 1);
    let (mut agree, mut total) = (0, 0);
    for i in 0..4000u64 {
        let o = DVec3::new(
            key.uniform(6 * i) * n as f64,
            -key.uniform(6 * i + 1) * n as f64,
            4.0,
        );
        let d = dir(
            360.0 * key.uniform(6 * i + 2),
            89.0 * key.uniform(6 * i + 3),
        ) * -1.0;
        let a = Tracer::trace(&hf, o, d, None);
        let b = tr.trace(o, d, None);
        total += 1;
        match (a, b) {
            (Some(a), Some(b)) => {
                assert!((a.t - b.t).abs() < 1e-7 * (1.0 + a.t), "{a:?} {b:?}");
                let (pa, fa) = Tracer::wrap(&hf, o + a.t * d, a.facet);
                let (pb, fb) = tr.wrap(o + b.t * d, b.facet);
                assert!((pa - pb).length() < 1e-6);
                if hf.facet_index(fa) == tr.facet_index(fb) {
                    agree += 1;
                }
                // upward rays from the hit: the same occlusion
                let up = dir(
                    360.0 * key.uniform(6 * i + 4),
                    85.0 * key.uniform(6 * i + 5),
                );
                if a.normal.dot(up) > 1e-3 {
                    assert_eq!(
                        hf.occluded(pa, up, Some(fa)),
                        tr.occluded(pb, up, Some(fb)),
                        "shadow ray {i}"
                    );
                }
            }
            (None, None) => agree += 1,
            (a, b) => panic!("ray {i}: heightfield {a:?}, mesh {b:?}"),
        }
    }
    // facets differ only for hits on a shared edge
    assert!(agree as f64 > 0.999 * total as f64, "{agree}/{total}");
}

#[test]
fn mesh_and_heightfield_give_the_same_brf() {
    let n = 16;
    let z = rough(n, 2.0, 5);
    let hf = Scene::new(
        Heightfield::new(&z, n, n, (1.0, 1.0), true, Split::NeSw).unwrap(),
        lam(0.6),
    );
    let ms = Scene::new(
        MeshTracer::new(&tile_mesh(&z, n, n), true, tile_extent(n, n)).unwrap(),
        lam(0.6),
    );
    for (sun, view) in [((0.0, 30.0), (0.0, 0.0)), ((135.0, 60.0), (20.0, 40.0))] {
        let a = hf
            .brf(dir(sun.0, sun.1), dir(view.0, view.1), 20000, 5, 2)
            .unwrap();
        let b = ms
            .brf(dir(sun.0, sun.1), dir(view.0, view.1), 20000, 5, 2)
            .unwrap();
        // same seeds and the same surface: equal paths up to rounding
        assert!(
            (a.value - b.value).abs() < 3.0 * a.se.max(1e-9),
            "{a:?} {b:?}"
        );
        assert!((a.value - b.value).abs() < 1e-3 * a.value, "{a:?} {b:?}");
    }
}

#[test]
fn rough_periodic_mesh_conserves_energy() {
    let n = 16;
    let z = rough(n, 3.0, 7);
    let ms = Scene::new(
        MeshTracer::new(&tile_mesh(&z, n, n), true, tile_extent(n, n)).unwrap(),
        lam(1.0),
    );
    for zen in [0.0, 45.0, 80.0] {
        let a = ms.albedo(dir(30.0, zen), 20000, 100_000, 3).unwrap();
        assert!((a.value - 1.0).abs() < 1e-3, "zenith {zen}: {a:?}");
    }
}

#[test]
fn lambertian_nadir_single_scattering_on_a_mesh() {
    // rho sum(A nz^2) / sum(A nz) for nadir sun and view, single scattering
    let n = 10;
    let z = rough(n, 2.5, 11);
    let tr = MeshTracer::new(&tile_mesh(&z, n, n), true, tile_extent(n, n)).unwrap();
    let (mut s2, mut s1) = (0.0, 0.0);
    for (a, nn) in tr.facets() {
        s2 += a * nn.z * nn.z;
        s1 += a * nn.z;
    }
    let s = Scene::new(tr, lam(0.8));
    let e = s.brf(DVec3::Z, DVec3::Z, 40000, 1, 4).unwrap();
    let want = 0.8 * s2 / s1;
    assert!(
        (e.value - want).abs() < 3.0 * e.se + 1e-9,
        "{e:?} vs {want}"
    );
}

#[test]
fn checkerboard_of_two_materials() {
    let (rows, cols) = (4, 6);
    let mesh = tile_mesh(&vec![0.0; rows * cols], rows, cols);
    let ids: Vec<u32> = (0..rows * cols)
        .flat_map(|k| {
            let m = ((k / cols + k % cols) % 2) as u32;
            [m, m]
        })
        .collect();
    let (ra, rb) = (0.2, 0.7);
    let tr = MeshTracer::new(&mesh, true, tile_extent(rows, cols)).unwrap();
    let s = Scene::with_materials(tr, vec![lam(ra), lam(rb)], ids.clone()).unwrap();
    let sun = dir(0.0, 60.0);
    let img = s.render(sun, DVec3::Z, (rows, cols), 8, 3, 0).unwrap();
    for i in 0..rows {
        for j in 0..cols {
            let rho = if (i + j) % 2 == 0 { ra } else { rb };
            let want = rho * sun.z / std::f64::consts::PI;
            assert!((img[i * cols + j] as f64 - want).abs() < 1e-6, "({i}, {j})");
        }
    }
    // the same ids on the heightfield
    let hf = Heightfield::new(
        &vec![0.0; rows * cols],
        rows,
        cols,
        (1.0, 1.0),
        true,
        Split::NeSw,
    )
    .unwrap();
    let s = Scene::with_materials(hf, vec![lam(ra), lam(rb)], ids).unwrap();
    let img2 = s.render(sun, DVec3::Z, (rows, cols), 8, 3, 0).unwrap();
    for (a, b) in img.iter().zip(&img2) {
        assert!((a - b).abs() < 1e-6);
    }
}

#[test]
fn mesh_results_do_not_depend_on_threads() {
    let n = 8;
    let z = rough(n, 2.0, 2);
    let mk = || {
        Scene::new(
            MeshTracer::new(&tile_mesh(&z, n, n), true, tile_extent(n, n)).unwrap(),
            lam(0.7),
        )
    };
    let run = |threads| {
        run_in_pool(Some(threads), || {
            let s = mk();
            let b = s.brf(dir(10.0, 40.0), dir(200.0, 30.0), 5000, 10, 8)?;
            let a = s.albedo(dir(10.0, 40.0), 5000, 10, 8)?;
            let img = s.render(dir(10.0, 40.0), DVec3::Z, (8, 8), 4, 10, 8)?;
            Ok((b, a, img))
        })
        .unwrap()
    };
    assert_eq!(run(1), run(2));
}

#[test]
fn triangles_across_the_tile_edge_are_wrapped() {
    // the flat tile as a triangle soup shifted by half a cell (east) and a
    // quarter (south), each triangle whose centroid left the tile moved
    // back by one tile: triangles cross the sides; still a plane, so BRF =
    // rho exactly
    let grid = tile_mesh(&[0.0; 16], 4, 4);
    let mut mesh = Mesh::default();
    for f in &grid.faces {
        let mut p = f.map(|i| grid.vertices[i as usize]);
        for v in &mut p {
            v[0] += 0.5;
            v[1] -= 0.25;
        }
        let cx = (p[0][0] + p[1][0] + p[2][0]) / 3.0;
        let cy = (p[0][1] + p[1][1] + p[2][1]) / 3.0;
        for v in &mut p {
            if cx > 4.0 {
                v[0] -= 4.0;
            }
            if cy < -4.0 {
                v[1] += 4.0;
            }
        }
        let k = mesh.vertices.len() as u32;
        mesh.vertices.extend(p);
        mesh.faces.push([k, k + 1, k + 2]);
    }
    let tr = MeshTracer::new(&mesh, true, tile_extent(4, 4)).unwrap();
    assert!(tr.primitive_count() > mesh.faces.len());
    let s = Scene::new(tr, lam(0.5));
    let e = s
        .brf(dir(70.0, 75.0), dir(250.0, 60.0), 3000, 4, 0)
        .unwrap();
    assert!((e.value - 0.5).abs() < 1e-6, "{e:?}");
    let a = s.albedo(dir(70.0, 75.0), 3000, 4, 0).unwrap();
    assert!((a.value - 0.5).abs() < 1e-6, "{a:?}");
}

#[test]
fn bad_meshes_and_materials_name_the_parameter() {
    let good = tile_mesh(&[0.0; 4], 2, 2);
    let err =
        |m: &Mesh, ext: Option<[f64; 4]>| MeshTracer::new(m, true, ext).unwrap_err().to_string();
    let mut m = good.clone();
    m.vertices[1][2] = f32::NAN;
    assert!(err(&m, None).starts_with("mesh:"));
    let mut m = good.clone();
    m.faces[0] = [0, 0, 1];
    let e = err(&m, None);
    assert!(e.starts_with("mesh:") && e.contains("degenerate"), "{e}");
    let mut m = good.clone();
    m.faces[2][1] = 99;
    assert!(err(&m, None).starts_with("mesh:"));
    assert!(err(&Mesh::default(), None).starts_with("mesh:"));
    let e = err(&good, Some([0.0, -1.0, 1.0, 1.0]));
    assert!(e.starts_with("extent:") && e.contains("cover"), "{e}");
    assert!(err(&good, Some([0.0, 0.0, -1.0, 1.0])).starts_with("extent:"));
    assert!(err(&good, Some([0.0, f64::NAN, 1.0, 1.0])).starts_with("extent:"));
    let tr = || MeshTracer::new(&good, true, None).unwrap();
    let e = Scene::with_materials(tr(), vec![lam(0.1)], vec![0; 7])
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("material_ids:"), "{e}");
    let e = Scene::with_materials(tr(), vec![lam(0.1), lam(0.2)], vec![2; 8])
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("material_ids:") && e.contains("2 materials"),
        "{e}"
    );
    let e = Scene::with_materials(tr(), vec![], vec![0; 8])
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("materials:"), "{e}");
}

/// A two-sided leaf for the tests: reflectance `r` on the side the light
/// comes from, transmittance `t` to the other, both Lambertian.
#[derive(Debug)]
struct TestLeaf {
    r: f64,
    t: f64,
}

impl Bsdf for TestLeaf {
    fn eval(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z * wo.z > 0.0 {
            self.r / std::f64::consts::PI
        } else {
            self.t / std::f64::consts::PI
        }
    }
    fn sample(&self, wo: DVec3, u: [f64; 2]) -> Option<material::BsdfSample> {
        let p = self.r / (self.r + self.t);
        let (reflect, u0) = if u[0] < p {
            (true, u[0] / p)
        } else {
            (false, (u[0] - p) / (1.0 - p))
        };
        let mut wi = material::cosine_hemisphere([u0, u[1]]);
        if !reflect {
            wi.z = -wi.z;
        }
        let _ = wo;
        let pdf = if reflect { p } else { 1.0 - p } * wi.z.abs() / std::f64::consts::PI;
        Some(material::BsdfSample {
            wi,
            weight: self.r + self.t,
            pdf,
        })
    }
    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        let p = self.r / (self.r + self.t);
        let q = if wi.z * wo.z > 0.0 { p } else { 1.0 - p };
        q * wi.z.abs() / std::f64::consts::PI
    }
    fn albedo(&self, _wo: DVec3) -> f64 {
        self.r + self.t
    }
    fn transmits(&self) -> bool {
        true
    }
}

#[test]
fn a_transmitting_leaf_layer_over_the_ground_matches_adding() {
    // a horizontal leaf layer (r, t) 1 m above Lambertian ground (rho):
    // BRF = albedo = r + t^2 rho / (1 - r rho) for every sun and view
    // (diffuse adding of two layers); exercises transmitted sampling and
    // next-event estimation through a leaf lit from behind
    let leaf = tile_mesh(&[1.0; 16], 4, 4);
    let ground = tile_mesh(&[0.0; 16], 4, 4);
    let mut mesh = leaf.clone();
    let k = mesh.vertices.len() as u32;
    mesh.vertices.extend(&ground.vertices);
    mesh.faces
        .extend(ground.faces.iter().map(|f| f.map(|i| i + k)));
    let ids: Vec<u32> = (0..mesh.faces.len())
        .map(|i| (i >= leaf.faces.len()) as u32)
        .collect();
    let (r, t, rho) = (0.3, 0.5, 0.6);
    let want = r + t * t * rho / (1.0 - r * rho);
    let tr = MeshTracer::new(&mesh, true, tile_extent(4, 4)).unwrap();
    let s = Scene::with_materials(tr, vec![Box::new(TestLeaf { r, t }), lam(rho)], ids).unwrap();
    for (sun, view) in [((0.0, 0.0), (0.0, 0.0)), ((60.0, 50.0), (250.0, 35.0))] {
        let e = s
            .brf(dir(sun.0, sun.1), dir(view.0, view.1), 40000, 200, 1)
            .unwrap();
        assert!((e.value - want).abs() < 3.0 * e.se, "{e:?} vs {want}");
        let a = s.albedo(dir(sun.0, sun.1), 40000, 200, 1).unwrap();
        assert!((a.value - want).abs() < 3.0 * a.se, "{a:?} vs {want}");
    }
}

mod instancing {
    use super::*;
    use crate::radiometry::InstancedTracer;
    use glam::{DAffine3, DMat3};

    #[test]
    fn four_translated_copies_match_the_whole_mesh() {
        // a periodic 4 x 4 tile placed 2 x 2 times is the 8 x 8 tile of the
        // same surface repeated
        let z4 = rough(4, 1.5, 21);
        let piece = tile_mesh(&z4, 4, 4);
        let mut z8 = vec![0.0; 64];
        for r in 0..8 {
            for c in 0..8 {
                z8[r * 8 + c] = z4[(r % 4) * 4 + c % 4];
            }
        }
        let whole = Scene::new(
            MeshTracer::new(&tile_mesh(&z8, 8, 8), true, tile_extent(8, 8)).unwrap(),
            lam(0.7),
        );
        let inst: Vec<(usize, DAffine3)> = [(0.0, 0.0), (4.0, 0.0), (0.0, -4.0), (4.0, -4.0)]
            .iter()
            .map(|&(x, y)| (0, DAffine3::from_translation(DVec3::new(x, y, 0.0))))
            .collect();
        let tr = InstancedTracer::new(&[piece], &inst, true, [0.0, -8.0, 8.0, 8.0]).unwrap();
        assert_eq!(tr.facet_count(), 4 * 32);
        let (s1, s2) = whole
            .hf
            .facets()
            .iter()
            .fold((0.0, 0.0), |a, f| (a.0 + f.0, a.1 + f.0 * f.1.z));
        let (i1, i2) = tr
            .facets()
            .iter()
            .fold((0.0, 0.0), |a, f| (a.0 + f.0, a.1 + f.0 * f.1.z));
        assert!((s1 - i1).abs() < 1e-9 * s1 && (s2 - i2).abs() < 1e-9 * s2);
        let inst_scene = Scene::new(tr, lam(0.7));
        for (sun, view) in [((0.0, 30.0), (0.0, 0.0)), ((135.0, 60.0), (20.0, 40.0))] {
            let a = whole
                .brf(dir(sun.0, sun.1), dir(view.0, view.1), 20000, 5, 2)
                .unwrap();
            let b = inst_scene
                .brf(dir(sun.0, sun.1), dir(view.0, view.1), 20000, 5, 2)
                .unwrap();
            assert!((a.value - b.value).abs() < 3.0 * a.se, "{a:?} {b:?}");
            let aa = whole.albedo(dir(sun.0, sun.1), 20000, 5, 2).unwrap();
            let ba = inst_scene.albedo(dir(sun.0, sun.1), 20000, 5, 2).unwrap();
            assert!((aa.value - ba.value).abs() < 3.0 * aa.se, "{aa:?} {ba:?}");
        }
    }

    #[test]
    fn rotated_scaled_plane_instances_give_rho_and_per_instance_materials() {
        // a unit square (two triangles) scaled by 2, rotated 90 degrees and
        // placed four times to cover the 4 x 4 tile: a flat plane
        let sq = Mesh {
            vertices: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [1.0, 1.0, 0.0],
            ],
            faces: vec![[0, 1, 2], [1, 3, 2]],
            ..Mesh::default()
        };
        let rot = DMat3::from_rotation_z(std::f64::consts::FRAC_PI_2) * 2.0;
        let inst: Vec<(usize, DAffine3)> = [(2.0, -4.0), (4.0, -4.0), (2.0, -2.0), (4.0, -2.0)]
            .iter()
            .map(|&(x, y)| {
                (
                    0,
                    DAffine3::from_mat3_translation(rot, DVec3::new(x, y, 0.5)),
                )
            })
            .collect();
        let tr = InstancedTracer::new(&[sq], &inst, true, [0.0, -4.0, 4.0, 4.0]).unwrap();
        for (a, n) in tr.facets() {
            assert!((a - 2.0).abs() < 1e-12 && (n.z - 1.0).abs() < 1e-12);
        }
        let ids = vec![0, 0, 1, 1, 1, 1, 0, 0]; // instances 0 and 3 dark
        let s = Scene::with_materials(tr, vec![lam(0.2), lam(0.6)], ids).unwrap();
        let e = s
            .brf(dir(40.0, 50.0), dir(220.0, 30.0), 20000, 4, 0)
            .unwrap();
        assert!((e.value - 0.4).abs() < 3.0 * e.se, "{e:?}");
        let img = s
            .render(dir(0.0, 60.0), DVec3::Z, (2, 2), 16, 4, 0)
            .unwrap();
        // image row 0 is north (y in [-2, 0]): instances 2 (x 0..2) and 3
        let want = [0.6, 0.2, 0.2, 0.6].map(|r| r * 0.5 / std::f64::consts::PI);
        for (p, w) in img.iter().zip(want) {
            assert!((*p as f64 - w).abs() < 1e-6, "{img:?}");
        }
        let bad = InstancedTracer::new(&[], &[(0, DAffine3::IDENTITY)], true, [0.0, 0.0, 1.0, 1.0]);
        assert!(bad.unwrap_err().to_string().starts_with("instances:"));
    }
}
