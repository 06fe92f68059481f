//! Tests against closed forms, invariants and an independent brute-force
//! ray caster.
use super::direction;
use super::heightfield::{Heightfield, Split};
use super::integrator::Scene;
use super::material::{self, Bsdf};
use super::oren_nayar::OrenNayar;
use crate::error::CoreError;
use crate::parallel::run_in_pool;
use crate::rng::StreamKey;
use glam::DVec3;

/// A periodic rough surface: a sum of random Fourier modes of an `n x n`
/// tile (heights in metres for 1 m cells), amplitude `amp`.
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
    z
}

fn scene(z: &[f64], rows: usize, cols: usize, periodic: bool, mat: &str, p: &[f64]) -> Scene {
    Scene::new(
        Heightfield::new(z, rows, cols, (1.0, 1.0), periodic, Split::NeSw).unwrap(),
        material::from_name(mat, p).unwrap(),
    )
}

fn dir(az: f64, zen: f64) -> DVec3 {
    direction((az, zen), "sun").unwrap()
}

#[test]
fn directions_follow_the_conventions() {
    // (east, north, up): azimuth 90 = east, azimuth 0 = north
    let e = dir(90.0, 90.0 - 1e-9);
    assert!((e - DVec3::X).length() < 1e-6);
    let n = dir(0.0, 60.0);
    assert!((n - DVec3::new(0.0, 60f64.to_radians().sin(), 0.5)).length() < 1e-12);
    for bad in [(0.0, 90.0), (0.0, -1.0), (f64::NAN, 0.0), (0.0, 120.0)] {
        let e = direction(bad, "sun").unwrap_err().to_string();
        assert!(e.starts_with("sun: "), "{e}");
    }
}

/// Möller & Trumbore (1997) on explicit triangles (vertex `(r, c)` at
/// `(c, -r, z)`) of `tiles x tiles` copies of the tile (periodic) or of the
/// patch alone: the nearest hit's t and normal.
fn brute(
    z: &[f64],
    rows: usize,
    cols: usize,
    periodic: bool,
    o: DVec3,
    d: DVec3,
    tiles: i64,
) -> Option<(f64, DVec3)> {
    let h = |r: i64, c: i64| {
        z[(r.rem_euclid(rows as i64) as usize) * cols + c.rem_euclid(cols as i64) as usize]
    };
    let (ncr, ncc) = if periodic {
        (rows as i64, cols as i64)
    } else {
        (rows as i64 - 1, cols as i64 - 1)
    };
    let range = if periodic { -tiles..=tiles } else { 0..=0 };
    let mut best: Option<(f64, DVec3)> = None;
    for ty in range.clone() {
        for tx in range.clone() {
            for r in 0..ncr {
                for c in 0..ncc {
                    let (gx, gy) = (c + tx * ncc, r + ty * ncr);
                    let v = |dr: i64, dc: i64| {
                        DVec3::new((gx + dc) as f64, -((gy + dr) as f64), h(r + dr, c + dc))
                    };
                    let (nw, ne, sw, se) = (v(0, 0), v(0, 1), v(1, 0), v(1, 1));
                    for tri in [[nw, ne, sw], [ne, se, sw]] {
                        let e1 = tri[1] - tri[0];
                        let e2 = tri[2] - tri[0];
                        let pv = d.cross(e2);
                        let det = e1.dot(pv);
                        if det.abs() < 1e-14 {
                            continue;
                        }
                        let tv = o - tri[0];
                        let u = tv.dot(pv) / det;
                        let qv = tv.cross(e1);
                        let w = d.dot(qv) / det;
                        let t = e2.dot(qv) / det;
                        if u >= 0.0
                            && w >= 0.0
                            && u + w <= 1.0
                            && t > 1e-10
                            && best.is_none_or(|b| t < b.0)
                        {
                            let mut n = e1.cross(e2).normalize();
                            if n.z < 0.0 {
                                n = -n;
                            }
                            best = Some((t, n));
                        }
                    }
                }
            }
        }
    }
    best
}

#[test]
fn traversal_agrees_with_brute_force_periodic_and_not() {
    // (6, 8) with blocks of 2 x 2 cells exercises the coarse level
    for (rows, cols, bside) in [(5, 7, 0), (6, 8, 2), (6, 8, 4)] {
        traversal_case(rows, cols, bside);
    }
}

fn traversal_case(rows: usize, cols: usize, bside: usize) {
    let z = rough(7, 3.0, 4)[..rows * cols].to_vec();
    let key = StreamKey::new(11, 1);
    for periodic in [true, false] {
        let mut hf = Heightfield::new(&z, rows, cols, (1.0, 1.0), periodic, Split::NeSw).unwrap();
        hf.set_block_side(bside);
        let mut hits = 0;
        for i in 0..3000u64 {
            let u = |k: u64| key.uniform(10 * i + k);
            let o = DVec3::new(
                u(0) * 9.0 - 1.0,
                1.0 - u(1) * 7.0,
                hf.zmin + u(2) * (hf.zmax - hf.zmin + 2.0),
            );
            // directions mostly downward but some climbing, some grazing
            let d = DVec3::new(u(3) - 0.5, u(4) - 0.5, -0.9 * u(5) + 0.25).normalize();
            let mine = hf.intersect(o, d, None);
            // the shadow-ray test agrees, and stops at t_max
            assert_eq!(hf.occluded(o, d, None, f64::INFINITY), mine.is_some());
            if let Some(h) = mine {
                assert!(hf.occluded(o, d, None, h.t * (1.0 + 1e-9)));
            }
            let theirs = brute(&z, rows, cols, periodic, o, d, 6);
            // origin below the surface: both may disagree on which side; skip
            let below = {
                let probe = hf.intersect(DVec3::new(o.x, o.y, hf.zmax + 1.0), -DVec3::Z, None);
                probe.is_some_and(|p| hf.zmax + 1.0 - p.t > o.z)
            };
            if below {
                continue;
            }
            match (mine, theirs) {
                (Some(a), Some((t, n))) => {
                    hits += 1;
                    assert!(
                        (a.t - t).abs() < 1e-9 * (1.0 + t),
                        "periodic={periodic} i={i} {} {t}",
                        a.t
                    );
                    assert!((a.normal - n).length() < 1e-9);
                }
                (None, None) => {}
                // the brute force sees only 13 x 13 tiles: a far hit it misses is fine
                (Some(a), None) if periodic && a.t > 6.0 * 5.0 => {}
                (a, b) => {
                    panic!("periodic={periodic} bside={bside} i={i}: {a:?} vs {b:?} o={o} d={d}")
                }
            }
        }
        assert!(hits > if periodic { 1000 } else { 300 }, "{hits}");
    }
}

/// Rays leaving the surface upwards, steep ones included (those the
/// Lipschitz escape test ends at once), find the same hit as the brute
/// force; so do steep rays starting below the surface (which must not be
/// taken for escaping ones).
#[test]
fn steep_rays_from_and_below_the_surface_agree_with_brute_force() {
    let (rows, cols) = (5, 7);
    let z = rough(7, 3.0, 4)[..rows * cols].to_vec();
    let key = StreamKey::new(12, 3);
    for periodic in [true, false] {
        let hf = Heightfield::new(&z, rows, cols, (1.0, 1.0), periodic, Split::NeSw).unwrap();
        let (mut escaped, mut hits) = (0, 0);
        for i in 0..4000u64 {
            let u = |k: u64| key.uniform(10 * i + k);
            let (x, y) = (0.05 + u(0) * 5.9, -0.05 - u(1) * 3.9);
            let top = DVec3::new(x, y, hf.zmax + 1.0);
            let probe = hf.intersect(top, -DVec3::Z, None).unwrap();
            let below = i % 4 == 0;
            let o = top - (probe.t + if below { 0.05 + u(2) } else { 0.0 }) * DVec3::Z;
            let skip = (!below).then_some(probe.facet);
            // elevation 20-90 degrees: most above the steepest facet's
            let elev = (20.0 + 70.0 * u(3)).to_radians();
            let az = std::f64::consts::TAU * u(4);
            let d = DVec3::new(elev.cos() * az.cos(), elev.cos() * az.sin(), elev.sin());
            let mine = hf.intersect(o, d, skip);
            assert_eq!(hf.occluded(o, d, skip, f64::INFINITY), mine.is_some());
            let theirs = brute(&z, rows, cols, periodic, o, d, 6)
                .filter(|&(t, _)| below || t > 1e-7 * (1.0 + o.z.abs()));
            match (mine, theirs) {
                (Some(a), Some((t, n))) => {
                    hits += 1;
                    assert!((a.t - t).abs() < 1e-9 * (1.0 + t), "i={i} {} {t}", a.t);
                    assert!((a.normal - n).length() < 1e-9);
                }
                (None, None) => escaped += 1,
                (Some(a), None) if periodic && a.t > 6.0 * 5.0 => {}
                (a, b) => {
                    panic!("periodic={periodic} i={i} below={below}: {a:?} vs {b:?} o={o} d={d}")
                }
            }
            if below && periodic {
                // (a finite patch may be left through its side first)
                assert!(
                    mine.is_some(),
                    "a ray from below the surface must hit it (i={i})"
                );
            }
        }
        assert!(escaped > 1000 && hits > 1000, "{escaped} {hits}");
    }
}

/// On a grid large enough for the coarse level, every ray (long and
/// shallow ones included) finds the same facet at the same `t` as the plain
/// cell walk, and the shadow-ray test agrees.
#[test]
fn coarse_level_changes_no_hit() {
    let n = 128;
    let z = rough(n, 12.0, 9);
    let key = StreamKey::new(5, 2);
    for periodic in [true, false] {
        let fast = Heightfield::new(&z, n, n, (1.0, 1.5), periodic, Split::NwSe).unwrap();
        let mut plain = fast.clone();
        plain.set_block_side(0);
        let mut hits = 0;
        for i in 0..20_000u64 {
            let u = |k: u64| key.uniform(10 * i + k);
            let o = DVec3::new(
                u(0) * n as f64,
                -u(1) * 1.5 * n as f64,
                fast.zmin + u(2) * (fast.zmax - fast.zmin) * 1.2,
            );
            let d = DVec3::new(u(3) - 0.5, u(4) - 0.5, 0.6 * (u(5) - 0.6)).normalize();
            let (a, b) = (fast.intersect(o, d, None), plain.intersect(o, d, None));
            match (a, b) {
                (Some(a), Some(b)) => {
                    hits += 1;
                    assert_eq!((a.t, a.facet), (b.t, b.facet), "periodic={periodic} i={i}");
                }
                (None, None) => {}
                (a, b) => panic!("periodic={periodic} i={i}: {a:?} vs {b:?}"),
            }
            assert_eq!(fast.occluded(o, d, None, f64::INFINITY), b.is_some());
        }
        assert!(hits > 5000, "{hits}");
    }
}

#[test]
fn flat_plane_brf_and_albedo_are_rho_exactly() {
    let z = vec![2.5; 16];
    for periodic in [true, false] {
        let s = scene(&z, 4, 4, periodic, "lambertian", &[0.37]);
        for (sun, view) in [
            ((0.0, 0.0), (0.0, 0.0)),
            ((135.0, 60.0), (10.0, 30.0)),
            ((270.0, 85.0), (90.0, 0.0)),
        ] {
            for depth in [1, 5] {
                let e = s
                    .brf(dir(sun.0, sun.1), dir(view.0, view.1), 2000, depth, 1)
                    .unwrap();
                if periodic || (sun.1 == 0.0 && view.1 == 0.0) {
                    // exact up to rounding; the SE at the rounding floor
                    assert!(
                        (e.value - 0.37).abs() < 1e-9,
                        "{periodic} {sun:?} {view:?} {e:?}"
                    );
                    assert!(e.se > 0.0 && e.se < 1e-11, "{e:?}");
                }
            }
            if periodic {
                let a = s.albedo(dir(sun.0, sun.1), 2000, 5, 1).unwrap();
                assert!((a.value - 0.37).abs() < 1e-6 && a.se < 1e-6, "{a:?}");
            }
        }
    }
}

#[test]
fn nadir_single_scattering_is_the_area_weighted_nz() {
    let n = 12;
    let z = rough(n, 4.0, 2);
    let rho = 0.6;
    // independent facet sums from explicit vertices
    let h = |r: usize, c: usize| z[(r % n) * n + c % n];
    let (mut num, mut den) = (0.0, 0.0);
    for r in 0..n {
        for c in 0..n {
            let v = |dr: usize, dc: usize| {
                DVec3::new((c + dc) as f64, -((r + dr) as f64), h(r + dr, c + dc))
            };
            for [a, b, cc] in [[v(0, 0), v(1, 0), v(0, 1)], [v(0, 1), v(1, 0), v(1, 1)]] {
                let cr = (b - a).cross(cc - a); // counter-clockwise from above: up
                assert!(cr.z > 0.0);
                let area = 0.5 * cr.length();
                let nz = cr.z / cr.length();
                num += area * nz * nz;
                den += area * nz;
            }
        }
    }
    let expect = rho * num / den;
    let s = scene(&z, n, n, true, "lambertian", &[rho]);
    let e = s.brf(DVec3::Z, DVec3::Z, 200_000, 1, 3).unwrap();
    assert!((e.value - expect).abs() < 3.0 * e.se, "{e:?} vs {expect}");
    assert!(expect < 0.95 * rho); // the surface is rough enough to matter
}

fn v_grooves(slope_deg: f64, n: usize) -> Vec<f64> {
    // grooves along the rows (north-south), period 2 columns
    let h = slope_deg.to_radians().tan();
    let mut z = vec![0.0; n * n];
    for r in 0..n {
        for c in 0..n {
            z[r * n + c] = if c % 2 == 0 { 0.0 } else { h };
        }
    }
    z
}

#[test]
fn v_grooves_single_scattering_nadir_is_rho_cos_s_for_any_sun() {
    let s_deg: f64 = 30.0;
    let z = v_grooves(s_deg, 8);
    let rho = 0.8;
    let expect = rho * s_deg.to_radians().cos();
    let sc = scene(&z, 8, 8, true, "lambertian", &[rho]);
    // sun across the grooves (azimuth 90/270), along them (0), oblique; lit
    // and shadowed (theta + s > 90, tan s tan theta > 1)
    for (az, zen) in [
        (0.0, 0.0),
        (90.0, 20.0),
        (270.0, 45.0),
        (90.0, 70.0),
        (90.0, 80.0),
        (0.0, 75.0),
        (40.0, 65.0),
    ] {
        let e = sc.brf(dir(az, zen), DVec3::Z, 100_000, 1, 5).unwrap();
        assert!(
            (e.value - expect).abs() < 3.0 * e.se + 1e-9,
            "sun ({az}, {zen}): {e:?} vs {expect}"
        );
    }
    // the oblique closed form in the plane across the grooves, nadir view:
    // L = rho/pi E 1/2 [f1 cos(theta - s) + f2 cos(theta + s)]; as BRF / cos(theta)
    // (f1 = min(1, 2/(1 + tan s tan theta)), f2 = 1 iff theta + s < 90).
    for zen in [20.0f64, 50.0, 70.0] {
        let (t, s) = (zen.to_radians(), s_deg.to_radians());
        let f1 = (2.0 / (1.0 + s.tan() * t.tan())).min(1.0);
        let f2 = if t + s < std::f64::consts::FRAC_PI_2 {
            1.0
        } else {
            0.0
        };
        let brf = rho * 0.5 * (f1 * (t - s).cos() + f2 * (t + s).cos()) / t.cos();
        assert!((brf - expect).abs() < 1e-12); // the identity, checked by hand
    }
}

#[test]
fn energy_is_conserved_with_rho_one() {
    let z = rough(16, 6.0, 9);
    let s = scene(&z, 16, 16, true, "lambertian", &[1.0]);
    for zen in [0.0, 45.0, 80.0] {
        let a = s.albedo(dir(30.0, zen), 20_000, 1000, 2).unwrap();
        assert!((a.value - 1.0).abs() < 1e-3, "zenith {zen}: {a:?}");
    }
    // and with fewer bounces some energy is still trapped
    let a = s.albedo(dir(30.0, 45.0), 20_000, 1, 2).unwrap();
    assert!(a.value < 0.995, "{a:?}");
}

#[test]
fn brf_is_reciprocal() {
    let z = rough(16, 5.0, 21);
    for (mat, p) in [("lambertian", vec![0.5]), ("oren-nayar", vec![0.7, 0.4])] {
        let s = scene(&z, 16, 16, true, mat, &p);
        for ((a1, z1), (a2, z2)) in [((0.0, 30.0), (180.0, 50.0)), ((45.0, 60.0), (100.0, 20.0))] {
            let (sun, view) = (dir(a1, z1), dir(a2, z2));
            let f = s.brf(sun, view, 200_000, 6, 7).unwrap();
            let b = s.brf(view, sun, 200_000, 6, 8).unwrap();
            // BRF * cos(sun) is the symmetric quantity; here the pair
            // BRF(sun, view) and BRF(view, sun) are equal as factors
            let tol = 3.0 * (f.se * f.se + b.se * b.se).sqrt();
            assert!((f.value - b.value).abs() < tol, "{mat}: {f:?} vs {b:?}");
        }
    }
}

#[test]
fn single_scattering_never_exceeds_multiple() {
    let z = rough(16, 5.0, 3);
    let mut last_share = f64::INFINITY;
    for rho in [0.9, 0.3, 0.05, 0.01] {
        let s = scene(&z, 16, 16, true, "lambertian", &[rho]);
        let (sun, view) = (dir(10.0, 40.0), dir(200.0, 25.0));
        let one = s.brf(sun, view, 20_000, 1, 4).unwrap();
        let many = s.brf(sun, view, 20_000, 20, 4).unwrap();
        assert!(one.value <= many.value, "{one:?} {many:?}");
        // the multiple-scattering share goes to 0 with rho (about as rho)
        let share = (many.value - one.value) / many.value;
        assert!(share < last_share, "{rho}: {share}");
        last_share = share;
    }
    assert!(last_share < 0.02, "{last_share}");
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let z = rough(8, 4.0, 5);
    let s = scene(&z, 8, 8, true, "lambertian", &[0.4]);
    let go = |n| {
        run_in_pool(Some(n), || {
            Ok((
                s.brf(dir(0.0, 30.0), dir(90.0, 10.0), 5000, 4, 9)?,
                s.albedo(dir(0.0, 30.0), 5000, 4, 9)?,
                s.render(dir(0.0, 30.0), DVec3::Z, (9, 11), 4, 3, 9)?,
            ))
        })
        .unwrap()
    };
    let (a, b) = (go(1), go(2));
    assert_eq!(a.0, b.0);
    assert_eq!(a.1, b.1);
    assert_eq!(a.2, b.2);
}

#[test]
fn image_mean_is_the_brf() {
    // flat: every pixel is rho/pi cos(theta) exactly
    let s = scene(&[1.0; 9], 3, 3, true, "lambertian", &[0.5]);
    let img = s.render(dir(0.0, 60.0), DVec3::Z, (4, 5), 3, 2, 0).unwrap();
    for v in img {
        assert!((v as f64 - 0.5 / std::f64::consts::PI * 0.5).abs() < 1e-7);
    }
}

#[test]
fn non_periodic_patches_lose_light_at_the_edges() {
    let z = rough(16, 5.0, 1);
    let p = scene(&z, 16, 16, true, "lambertian", &[1.0]);
    let f = scene(&z, 16, 16, false, "lambertian", &[1.0]);
    let sun = dir(90.0, 70.0);
    let ap = p.albedo(sun, 20_000, 200, 1).unwrap();
    let af = f.albedo(sun, 20_000, 200, 1).unwrap();
    assert!((ap.value - 1.0).abs() < 1e-3);
    assert!(af.value < 0.99, "{af:?}"); // sun rays leave through the sides
}

#[test]
fn oren_nayar_matches_its_closed_form() {
    let (rho, sigma) = (0.6, 0.35);
    let on = OrenNayar::new(rho, sigma).unwrap();
    let s2 = sigma * sigma;
    let (a, b) = (1.0 - 0.5 * s2 / (s2 + 0.33), 0.45 * s2 / (s2 + 0.09));
    let key = StreamKey::new(3, 3);
    let pi = std::f64::consts::PI;
    for i in 0..2000u64 {
        let (ti, to) = (key.uniform(4 * i) * 1.5, key.uniform(4 * i + 1) * 1.5);
        let (pi_, po) = (
            key.uniform(4 * i + 2) * 2.0 * pi,
            key.uniform(4 * i + 3) * 2.0 * pi,
        );
        let w = |t: f64, p: f64| DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
        let (al, be) = (ti.max(to), ti.min(to));
        let expect = rho / pi * (a + b * (pi_ - po).cos().max(0.0) * al.sin() * be.tan());
        let got = on.eval(w(ti, pi_), w(to, po));
        assert!((got - expect).abs() < 1e-12, "{got} {expect}");
        assert!((got - on.eval(w(to, po), w(ti, pi_))).abs() < 1e-15); // reciprocal
    }
    // nadir view: f = rho A / pi for any light
    assert!((on.eval(DVec3::new(0.6, 0.0, 0.8), DVec3::Z) - rho * a / pi).abs() < 1e-15);
    // energy bound at rho = 1, any view
    let one = OrenNayar::new(1.0, 1.0).unwrap();
    for t in [0.0f64, 0.5, 1.0, 1.4, 1.55] {
        let alb = one.albedo(DVec3::new(t.sin(), 0.0, t.cos()));
        assert!(alb <= 1.0 && alb > 0.5, "{t}: {alb}");
    }
}

#[test]
fn cosine_sampler_passes_chi_square() {
    // cos^2(theta) of a cosine-weighted direction is uniform on (0, 1)
    let l = material::from_name("lambertian", &[1.0]).unwrap();
    let key = StreamKey::new(1, 2);
    let (bins, n) = (20usize, 100_000u64);
    let mut count = vec![0u64; bins];
    for i in 0..n {
        let s = l
            .sample(DVec3::Z, [key.uniform(2 * i), key.uniform(2 * i + 1)])
            .unwrap();
        assert!((s.pdf - l.pdf(s.wi, DVec3::Z)).abs() < 1e-15);
        count[((s.wi.z * s.wi.z * bins as f64) as usize).min(bins - 1)] += 1;
    }
    let e = n as f64 / bins as f64;
    let chi2: f64 = count.iter().map(|&c| (c as f64 - e).powi(2) / e).sum();
    assert!(chi2 < 43.8, "{chi2}"); // 19 dof, p = 0.001
}

#[test]
fn bad_input_names_the_parameter() {
    let p = |e: CoreError| match e {
        CoreError::InvalidArgument { param, .. } => param,
        CoreError::OutOfMemory { param, .. } => format!("oom:{param}"),
        other => panic!("{other:?}"),
    };
    assert_eq!(
        p(material::from_name("lambertian", &[1.5]).unwrap_err()),
        "rho"
    );
    assert_eq!(
        p(material::from_name("oren-nayar", &[0.5, -1.0]).unwrap_err()),
        "sigma"
    );
    assert_eq!(
        p(material::from_name("hapke", &[0.5]).unwrap_err()),
        "material"
    );
    assert_eq!(
        p(Heightfield::new(
            &[0.0, f64::NAN, 0.0, 0.0],
            2,
            2,
            (1.0, 1.0),
            true,
            Split::NeSw
        )
        .unwrap_err()),
        "dem"
    );
    assert_eq!(
        p(Heightfield::new(&[0.0; 4], 2, 2, (1.0, 0.0), true, Split::NeSw).unwrap_err()),
        "cell_size"
    );
    assert_eq!(
        p(Heightfield::new(&[0.0; 2], 1, 2, (1.0, 1.0), false, Split::NeSw).unwrap_err()),
        "dem"
    );
    let s = scene(&[0.0; 4], 2, 2, true, "lambertian", &[0.5]);
    assert_eq!(p(s.brf(DVec3::Z, DVec3::Z, 0, 1, 0).unwrap_err()), "spp");
    assert_eq!(
        p(s.brf(DVec3::Z, DVec3::Z, 1, 0, 0).unwrap_err()),
        "max_depth"
    );
    assert_eq!(
        p(s.render(DVec3::Z, DVec3::Z, (100_000, 10_000), 1, 1, 0)
            .unwrap_err()),
        "oom:shape"
    );
    assert_eq!(
        p(s.render(DVec3::Z, DVec3::Z, (0, 3), 1, 1, 0).unwrap_err()),
        "shape"
    );
}

#[test]
fn nw_se_split_is_also_exact() {
    // a single tilted plane gives the same facets under either split
    let mut z = vec![0.0; 16];
    for r in 0..4 {
        for c in 0..4 {
            z[r * 4 + c] = 0.3 * c as f64 + 0.1 * r as f64;
        }
    }
    let a = Heightfield::new(&z, 4, 4, (1.0, 1.0), false, Split::NeSw).unwrap();
    let b = Heightfield::new(&z, 4, 4, (1.0, 1.0), false, Split::NwSe).unwrap();
    let o = DVec3::new(1.3, -1.7, 10.0);
    let (ha, hb) = (
        a.intersect(o, -DVec3::Z, None).unwrap(),
        b.intersect(o, -DVec3::Z, None).unwrap(),
    );
    assert!((ha.t - hb.t).abs() < 1e-12 && (ha.normal - hb.normal).length() < 1e-12);
    assert!((10.0 - ha.t - (0.3 * 1.3 + 0.1 * 1.7)).abs() < 1e-12);
}

#[test]
fn phong_matches_its_closed_form_and_its_sampler_its_density() {
    use super::phong::Phong;
    let pi = std::f64::consts::PI;
    let (kd, ks, n) = (0.3, 0.6, 12.0);
    let ph = Phong::new(kd, ks, n).unwrap();
    let key = StreamKey::new(5, 5);
    let w = |t: f64, p: f64| DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
    for i in 0..2000u64 {
        let (ti, to) = (key.uniform(4 * i) * 1.5, key.uniform(4 * i + 1) * 1.5);
        let (pi_, po) = (
            key.uniform(4 * i + 2) * 2.0 * pi,
            key.uniform(4 * i + 3) * 2.0 * pi,
        );
        // angle to the mirror direction (theta_o, phi_o + pi)
        let ca = ti.cos() * to.cos() - ti.sin() * to.sin() * (pi_ - po).cos();
        let expect = kd / pi + ks * (n + 2.0) / (2.0 * pi) * ca.max(0.0).powf(n);
        let got = ph.eval(w(ti, pi_), w(to, po));
        assert!(
            (got - expect).abs() < 1e-12 * (1.0 + expect),
            "{got} {expect}"
        );
        assert!((got - ph.eval(w(to, po), w(ti, pi_))).abs() < 1e-12 * (1.0 + got));
    }
    // normal incidence: albedo kd + ks exactly (quadrature to 1e-4)
    assert!((ph.albedo(DVec3::Z) - (kd + ks)).abs() < 1e-4);
    // the sampler's mean weight is the albedo (its pdf is its density)
    for t in [0.0f64, 0.7, 1.3] {
        let wo = DVec3::new(t.sin(), 0.0, t.cos());
        let m = 400_000u64;
        let (mut s1, mut s2) = (0.0, 0.0);
        for i in 0..m {
            if let Some(smp) = ph.sample(
                wo,
                [key.uniform(10_000 + 2 * i), key.uniform(10_001 + 2 * i)],
            ) {
                assert!((smp.pdf - ph.pdf(smp.wi, wo)).abs() < 1e-12 * (1.0 + smp.pdf));
                s1 += smp.weight;
                s2 += smp.weight * smp.weight;
            }
        }
        let mean = s1 / m as f64;
        let se = ((s2 / m as f64 - mean * mean) / m as f64).sqrt();
        let alb = ph.albedo(wo);
        assert!(
            (mean - alb).abs() < 4.0 * se + 1e-4,
            "{t}: {mean} +- {se} vs {alb}"
        );
        assert!(alb <= kd + ks + 1e-4);
    }
    // the lobe alone around the normal: cos(alpha)^(n+1) is uniform
    let lobe = Phong::new(0.0, 1.0, n).unwrap();
    let (bins, m) = (20usize, 100_000u64);
    let mut count = vec![0u64; bins];
    for i in 0..m {
        let s = lobe
            .sample(DVec3::Z, [key.uniform(2 * i), key.uniform(2 * i + 1)])
            .unwrap();
        count[((s.wi.z.powf(n + 1.0) * bins as f64) as usize).min(bins - 1)] += 1;
    }
    let e = m as f64 / bins as f64;
    let chi2: f64 = count.iter().map(|&c| (c as f64 - e).powi(2) / e).sum();
    assert!(chi2 < 43.8, "{chi2}");
    assert!(Phong::new(0.6, 0.6, 2.0).is_err());
}

#[test]
fn rectangular_cells_give_world_normals_and_exact_nadir_brf() {
    // the plane z = gx x + gy y (x east, y north) sampled with cells 2 m x 3 m
    let (gx, gy, dx, dy) = (0.4, -0.25, 2.0, 3.0);
    let (rows, cols) = (5, 6);
    let mut z = vec![0.0; rows * cols];
    for r in 0..rows {
        for c in 0..cols {
            z[r * cols + c] = gx * c as f64 * dx + gy * (-(r as f64) * dy);
        }
    }
    let n = DVec3::new(-gx, -gy, 1.0).normalize();
    for split in [Split::NeSw, Split::NwSe] {
        let hf = Heightfield::new(&z, rows, cols, (dx, dy), false, split).unwrap();
        let (x, y) = (3.7, -5.1);
        let hit = hf
            .intersect(DVec3::new(x, y, 100.0), -DVec3::Z, None)
            .unwrap();
        assert!((100.0 - hit.t - (gx * x + gy * y)).abs() < 1e-12);
        assert!((hit.normal - n).length() < 1e-12);
        // an oblique ray too
        let d = DVec3::new(0.3, -0.2, -0.9).normalize();
        let o = DVec3::new(1.0, -2.0, 5.0);
        let hit = hf.intersect(o, d, None).unwrap();
        let p = o + hit.t * d;
        assert!((p.z - (gx * p.x + gy * p.y)).abs() < 1e-9);
        for (area, nn) in hf.facets() {
            assert!((area - 0.5 * dx * dy / n.z).abs() < 1e-12 && (nn - n).length() < 1e-12);
        }
        // nadir sun and view on a plane: BRF = rho n_z exactly
        let s = Scene::new(hf, material::from_name("lambertian", &[0.6]).unwrap());
        let e = s.brf(DVec3::Z, DVec3::Z, 1000, 3, 0).unwrap();
        assert!((e.value - 0.6 * n.z).abs() < 1e-9, "{e:?}");
    }
}

/// A local-frame direction from (zenith, azimuth) in degrees, as in
/// Eradiate's test vectors.
fn local(zen: f64, az: f64) -> DVec3 {
    let (t, p) = (zen.to_radians(), az.to_radians());
    DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

/// (zenith, azimuth) in degrees.
type Angles = (f64, f64);

#[test]
fn hapke_matches_eradiate_reference_values() {
    // eradiate-mitsuba 0.5.0 `hapke` BSDF, scalar_mono_double, measured
    // (docs RADIOMETRY_REFERENCES.md 4.1): ((sun), (view), BRF)
    let a = material::from_name("hapke", &[0.5, 0.2, 0.4, 15.0, 1.0, 0.05]).unwrap();
    let b = material::from_name("hapke", &[0.8, 0.3, 0.6, 25.0, 0.0, 0.0]).unwrap();
    let cases: [(&dyn Bsdf, Angles, Angles, f64); 9] = [
        (&*a, (30.0, 0.0), (0.0, 0.0), 0.113820),
        (&*a, (30.0, 0.0), (30.0, 0.0), 0.192827),
        (&*a, (30.0, 0.0), (30.0, 180.0), 0.107831),
        (&*a, (60.0, 0.0), (45.0, 180.0), 0.139896),
        (&*a, (45.0, 180.0), (60.0, 0.0), 0.139896),
        (&*a, (60.0, 0.0), (20.0, 90.0), 0.122498),
        (&*a, (30.0, 0.0), (28.0, 0.0), 0.171040),
        (&*b, (30.0, 0.0), (0.0, 0.0), 0.288117),
        (&*b, (30.0, 0.0), (30.0, 180.0), 0.251600),
    ];
    for (m, s, v, want) in cases {
        let got = std::f64::consts::PI * m.eval(local(s.0, s.1), local(v.0, v.1));
        assert!((got - want).abs() < 1e-5, "{s:?} {v:?}: {got} vs {want}");
    }
    // (60, 0) -> (45, 180) of the second set, 0.215051
    let got = std::f64::consts::PI * b.eval(local(60.0, 0.0), local(45.0, 180.0));
    assert!((got - 0.215051).abs() < 1e-5, "{got}");
}

#[test]
fn hapke_is_finite_at_exact_backscatter_with_h_zero() {
    // Eradiate gives NaN here (0/0 in the opposition term)
    for b0 in [0.0, 1.0] {
        let m = material::from_name("hapke", &[0.8, 0.3, 0.6, 25.0, b0, 0.0]).unwrap();
        for (zen, az) in [(30.0, 0.0), (0.0, 0.0), (89.0, 45.0), (60.0, 270.0)] {
            let w = local(zen, az);
            let v = m.eval(w, w);
            assert!(v.is_finite() && v > 0.0, "{zen} {az}: {v}");
        }
        // continuous away from the surge (B0 = 0): the limit of nearby directions
        if b0 == 0.0 {
            let at = m.eval(local(30.0, 0.0), local(30.0, 0.0));
            let near = m.eval(local(30.0, 0.0), local(30.0 + 1e-6, 0.0));
            assert!((at - near).abs() < 1e-6, "{at} {near}");
        }
    }
}

#[test]
fn hapke_isotropic_smooth_case_is_chandrasekhar_form() {
    // theta_bar = 0, B0 = 0, b = 0 (P = 1): BRF = w/4 H(mu0) H(mu) / (mu0 + mu)
    // with Hapke's (2002) H(x) = 1 / (1 - w x (r0 + (1 - 2 r0 x)/2 ln((1+x)/x)))
    let w = 0.7f64;
    let m = material::from_name("hapke", &[w, 0.0, 0.5, 0.0, 0.0, 0.1]).unwrap();
    let r0 = (1.0 - (1.0 - w).sqrt()) / (1.0 + (1.0 - w).sqrt());
    let h = |x: f64| 1.0 / (1.0 - w * x * (r0 + (1.0 - 2.0 * r0 * x) / 2.0 * ((1.0 + x) / x).ln()));
    for (i, e, p) in [(10.0, 20.0, 30.0), (60.0, 5.0, 170.0), (45.0, 45.0, 90.0)] {
        let (wi, wo) = (local(i, 0.0), local(e, p));
        let want = w / 4.0 * h(wi.z) * h(wo.z) / (wi.z + wo.z);
        let got = std::f64::consts::PI * m.eval(wi, wo);
        assert!((got - want).abs() < 1e-12, "{got} {want}");
    }
}

#[test]
fn hapke_is_reciprocal_and_energy_bounded() {
    let key = StreamKey::new(7, 3);
    let params = [
        [0.5, 0.2, 0.4, 15.0, 1.0, 0.05],
        [0.8, 0.3, 0.6, 25.0, 0.0, 0.0],
        [0.95, 0.6, 0.1, 40.0, 0.5, 0.01],
        [0.3, 0.0, 1.0, 0.0, 1.0, 0.0],
    ];
    for p in params {
        let m = material::from_name("hapke", &p).unwrap();
        for i in 0..2000u64 {
            let wi = local(89.0 * key.uniform(4 * i), 360.0 * key.uniform(4 * i + 1));
            let wo = local(
                89.0 * key.uniform(4 * i + 2),
                360.0 * key.uniform(4 * i + 3),
            );
            let (a, b) = (m.eval(wi, wo), m.eval(wo, wi));
            assert!(a.is_finite() && a >= 0.0);
            assert!((a - b).abs() <= 1e-12 * a.max(1e-300), "{p:?}: {a} {b}");
        }
        for zen in (0..90).step_by(3) {
            let alb = m.albedo(local(zen as f64, 0.0));
            assert!(alb <= 1.0, "{p:?} at {zen}: {alb}");
        }
    }
    // Hapke's model exceeds 1 for bright back-scattering surfaces: rejected
    let err = material::from_name("hapke", &[1.0, 0.7, 1.0, 0.0, 1.0, 0.3]).unwrap_err();
    assert!(
        matches!(err, CoreError::InvalidArgument { ref param, .. } if param == "w"),
        "{err}"
    );
    for (k, bad) in [
        (0, 1.5),
        (1, 1.0),
        (2, -0.1),
        (3, 90.0),
        (4, f64::NAN),
        (5, 2.0),
    ] {
        let mut p = [0.5, 0.2, 0.4, 15.0, 1.0, 0.05];
        p[k] = bad;
        assert!(material::from_name("hapke", &p).is_err(), "{k} {bad}");
    }
}

#[test]
fn hapke_sampler_passes_chi_square_and_its_weight_is_the_albedo() {
    let m = material::from_name("hapke", &[0.6, 0.3, 0.7, 20.0, 1.0, 0.05]).unwrap();
    let key = StreamKey::new(3, 9);
    let wo = local(40.0, 30.0);
    let (bins, n) = (20usize, 200_000u64);
    let mut count = vec![0u64; bins];
    let (mut s1, mut s2) = (0.0, 0.0);
    for i in 0..n {
        let s = m
            .sample(wo, [key.uniform(2 * i), key.uniform(2 * i + 1)])
            .unwrap();
        assert!((s.pdf - m.pdf(s.wi, wo)).abs() < 1e-15);
        let want = m.eval(s.wi, wo) * s.wi.z / s.pdf;
        assert!((s.weight - want).abs() <= 1e-12 * want.max(1.0));
        s1 += s.weight;
        s2 += s.weight * s.weight;
        count[((s.wi.z * s.wi.z * bins as f64) as usize).min(bins - 1)] += 1;
    }
    let e = n as f64 / bins as f64;
    let chi2: f64 = count.iter().map(|&c| (c as f64 - e).powi(2) / e).sum();
    assert!(chi2 < 43.8, "{chi2}"); // 19 dof, p = 0.001
    let mean = s1 / n as f64;
    let se = ((s2 / n as f64 - mean * mean) / n as f64).sqrt();
    let alb = m.albedo(wo);
    assert!(
        (mean - alb).abs() < 4.0 * se + 1e-4,
        "{mean} +- {se} vs {alb}"
    );
}

#[test]
fn specular_mirror_reflects_the_fresnel_fraction() {
    // Fresnel at normal incidence: ((n - 1)^2 + k^2) / ((n + 1)^2 + k^2)
    for (n, k) in [(1.5, 0.0), (1.33, 0.0), (0.2, 3.5)] {
        let m = super::specular::Specular::new(n, k).unwrap();
        let want = ((n - 1.0f64).powi(2) + k * k) / ((n + 1.0f64).powi(2) + k * k);
        assert!((m.fresnel(1.0) - want).abs() < 1e-14, "{n} {k}");
        assert!((m.fresnel(0.0) - 1.0).abs() < 1e-14); // grazing
    }
    // dielectric at Brewster's angle: r_p = 0, so F = r_s / 2 with
    // r_s = ((n^2 - 1) / (n^2 + 1))^2
    let n = 1.5f64;
    let m = super::specular::Specular::new(n, 0.0).unwrap();
    let cb = (1.0 / (1.0 + n * n)).sqrt();
    let rs = ((n * n - 1.0) / (n * n + 1.0)).powi(2);
    assert!((m.fresnel(cb) - 0.5 * rs).abs() < 1e-14);
    // sampling: the mirror direction with weight F; eval and pdf are 0
    let wo = local(40.0, 30.0);
    let s = m.sample(wo, [0.3, 0.7]).unwrap();
    assert!((s.wi - DVec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-15);
    assert!((s.weight - m.fresnel(wo.z)).abs() < 1e-15 && m.eval(s.wi, wo) == 0.0);
    // a flat mirror: albedo = F(cos sun zenith) exactly, BRF 0 (a delta)
    let z = vec![0.0; 16];
    let sc = scene(&z, 4, 4, true, "specular", &[1.5, 0.0]);
    let brewster = n.atan().to_degrees();
    for (zen, want) in [(0.0, 0.04), (brewster, 0.5 * rs)] {
        let a = sc.albedo(dir(20.0, zen), 100, 10, 0).unwrap();
        assert!(
            (a.value - want).abs() < 1e-12 && a.se < 1e-8,
            "{zen}: {a:?} {want}"
        );
        assert_eq!(
            sc.brf(dir(20.0, zen), dir(200.0, zen), 100, 10, 0)
                .unwrap()
                .value,
            0.0
        );
    }
    assert!(material::from_name("specular", &[0.0, 0.0]).is_err());
    assert!(material::from_name("specular", &[1.5, -1.0]).is_err());
}

// ---- sky light, PSFs and the bi-hemispherical reflectance ----

#[test]
fn sky_zero_is_the_plain_brf_and_image() {
    let z = rough(12, 1.5, 3);
    let s = scene(&z, 12, 12, true, "lambertian", &[0.6]);
    let (sun, view) = (dir(120.0, 40.0), dir(300.0, 20.0));
    assert_eq!(
        s.brf(sun, view, 3000, 5, 7).unwrap(),
        s.brf_sky(sun, view, 0.0, 3000, 5, 7).unwrap()
    );
    let a = s.render(sun, view, (5, 4), 3, 5, 2).unwrap();
    let b = s
        .render_psf(
            sun,
            view,
            0.0,
            (5, 4),
            3,
            5,
            2,
            &super::integrator::Psf::Box,
            None,
        )
        .unwrap();
    assert_eq!(a, b);
}

#[test]
fn flat_lambertian_under_sun_and_sky() {
    // L = rho (cos(sun zenith) + E_sky) / pi exactly; the HDRF is rho
    let z = vec![0.0; 16];
    let rho = 0.4;
    let s = scene(&z, 4, 4, true, "lambertian", &[rho]);
    for (zen, sky) in [(0.0, 0.3), (60.0, 2.0), (80.0, 0.05)] {
        let sun = dir(33.0, zen);
        let e = s.brf_sky(sun, dir(0.0, 0.0), sky, 500, 1, 1).unwrap();
        assert!((e.value - rho).abs() < 1e-12, "{e:?}");
        let gauss = super::integrator::Psf::gaussian(0.8, 3.0).unwrap();
        let img = s
            .render_psf(sun, dir(200.0, 35.0), sky, (3, 3), 4, 3, 0, &gauss, None)
            .unwrap();
        let want = rho * (sun.z + sky) / std::f64::consts::PI;
        for v in img {
            assert!((v as f64 - want).abs() < 1e-6 * want, "{v} vs {want}");
        }
    }
    for bad in [-1.0, f64::NAN, f64::INFINITY] {
        let e = s.brf_sky(dir(0.0, 0.0), dir(0.0, 0.0), bad, 10, 1, 0);
        assert!(e.unwrap_err().to_string().starts_with("sky: "));
    }
}

#[test]
fn bhr_of_a_flat_plane_is_rho() {
    let z = vec![0.0; 16];
    let s = scene(&z, 4, 4, true, "lambertian", &[0.3]);
    let e = s.bhr(2000, 10, 4).unwrap();
    assert!((e.value - 0.3).abs() < 1e-12 && e.se < 1e-12, "{e:?}");
}

#[test]
fn psf_positions_follow_their_distributions() {
    use super::integrator::Psf;
    // truncated Gaussian: every draw inside the disc; the radial CDF at
    // sigma matches (1 - e^{-1/2}) / (1 - e^{-R^2/2 sigma^2})
    let g = Psf::gaussian(0.7, 2.0).unwrap();
    let n = 20000;
    let k = StreamKey::new(1, 2);
    let mut inside = 0;
    for i in 0..n {
        let (x, y) = g.position([k.uniform(2 * i), k.uniform(2 * i + 1)]);
        let r = ((x - 0.5).powi(2) + (y - 0.5).powi(2)).sqrt();
        assert!(r <= 1.4 + 1e-12);
        if r < 0.7 {
            inside += 1;
        }
    }
    let p = (1.0 - (-0.5f64).exp()) / (1.0 - (-2.0f64).exp());
    let f = inside as f64 / n as f64;
    assert!(
        (f - p).abs() < 4.0 * (p * (1.0 - p) / n as f64).sqrt(),
        "{f} {p}"
    );
    // table: a 1 x 2 grid with weights 1 and 3, cells of 2 pixels
    let t = Psf::table(&[1.0, 3.0], 1, 2, 2.0).unwrap();
    let mut right = 0;
    for i in 0..n {
        let (x, y) = t.position([k.uniform(2 * i), k.uniform(2 * i + 1)]);
        assert!((-1.5..=2.5).contains(&x) && (-0.5..=1.5).contains(&y));
        if x > 0.5 {
            right += 1;
        }
    }
    let f = right as f64 / n as f64;
    assert!((f - 0.75).abs() < 4.0 * (0.1875 / n as f64).sqrt(), "{f}");
    assert!(Psf::table(&[0.0, 0.0], 1, 2, 1.0).is_err());
    assert!(Psf::table(&[1.0, -1.0], 1, 2, 1.0).is_err());
    assert!(Psf::gaussian(0.0, 3.0).is_err());
}

// ---- full Oren-Nayar and the perspective camera ----

#[test]
fn full_oren_nayar_is_reciprocal_bounded_and_its_sampler_fits() {
    let m = material::from_name("oren-nayar-full", &[0.8, 0.4]).unwrap();
    let key = StreamKey::new(5, 1);
    for i in 0..2000u64 {
        let a = super::material::cosine_hemisphere([key.uniform(4 * i), key.uniform(4 * i + 1)]);
        let b =
            super::material::cosine_hemisphere([key.uniform(4 * i + 2), key.uniform(4 * i + 3)]);
        let (f1, f2) = (m.eval(a, b), m.eval(b, a));
        assert!(
            f1 >= 0.0 && (f1 - f2).abs() <= 1e-12 * f1.max(1e-300),
            "{f1} {f2}"
        );
    }
    // sigma = 0 is Lambertian
    let l = material::from_name("oren-nayar-full", &[0.6, 0.0]).unwrap();
    let (a, b) = (local(20.0, 10.0), local(70.0, 250.0));
    assert!((l.eval(a, b) - 0.6 / std::f64::consts::PI).abs() < 1e-15);
    // energy: rho = 1 and small sigma reflects more than the incident light at grazing
    let e = material::from_name("oren-nayar-full", &[1.0, 0.3])
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("rho: "), "{e}");
    let wo = local(50.0, 30.0);
    let (bins, n) = (20usize, 200_000u64);
    let mut count = vec![0u64; bins];
    let (mut s1, mut s2) = (0.0, 0.0);
    for i in 0..n {
        let s = m
            .sample(wo, [key.uniform(2 * i), key.uniform(2 * i + 1)])
            .unwrap();
        assert!((s.pdf - m.pdf(s.wi, wo)).abs() < 1e-15);
        let want = m.eval(s.wi, wo) * s.wi.z / s.pdf;
        assert!((s.weight - want).abs() <= 1e-12 * want.max(1.0));
        s1 += s.weight;
        s2 += s.weight * s.weight;
        count[((s.wi.z * s.wi.z * bins as f64) as usize).min(bins - 1)] += 1;
    }
    let ex = n as f64 / bins as f64;
    let chi2: f64 = count.iter().map(|&c| (c as f64 - ex).powi(2) / ex).sum();
    assert!(chi2 < 43.8, "{chi2}"); // 19 dof, p = 0.001
    let mean = s1 / n as f64;
    let se = ((s2 / n as f64 - mean * mean) / n as f64).sqrt();
    assert!(
        (mean - m.albedo(wo)).abs() < 4.0 * se + 1e-4,
        "{mean} +- {se}"
    );
}

#[test]
fn perspective_camera_over_a_flat_plane() {
    use super::integrator::Pinhole;
    let z = vec![0.0; 16];
    let rho = 0.5;
    let s = scene(&z, 4, 4, true, "lambertian", &[rho]);
    let sun = dir(10.0, 60.0);
    let sky = 0.4;
    // looking horizontally from 3 m: the top half of the image is sky, the
    // bottom half the lit plane, the horizon between the two middle rows
    let cam = Pinhole::new(DVec3::new(1.0, -1.0, 3.0), DVec3::new(1.0, 10.0, 3.0), 50.0).unwrap();
    let img = s
        .render_perspective(sun, sky, &cam, (6, 5), 8, 4, 1, None)
        .unwrap();
    let ground = rho * (sun.z + sky) / std::f64::consts::PI;
    let air = sky / std::f64::consts::PI;
    for (k, v) in img.iter().enumerate() {
        let want = if k / 5 < 3 { air } else { ground };
        assert!((*v as f64 - want).abs() < 1e-6, "{k}: {v} vs {want}");
    }
    assert!(Pinhole::new(DVec3::ZERO, DVec3::ZERO, 40.0).is_err());
    assert!(Pinhole::new(DVec3::ZERO, DVec3::Z, 180.0).is_err());
}

#[test]
fn orders_split_the_same_paths() {
    let z = rough(16, 5.0, 3);
    let s = scene(&z, 16, 16, true, "lambertian", &[0.7]);
    let (sun, view) = (dir(10.0, 40.0), dir(200.0, 25.0));
    for sky in [0.0, 0.3] {
        let o = s.brf_orders(sun, view, sky, 5000, 12, 4).unwrap();
        // single scattering is the max_depth = 1 run, total the full run, bit for bit
        assert_eq!(o.single, s.brf_sky(sun, view, sky, 5000, 1, 4).unwrap());
        assert_eq!(o.total, s.brf_sky(sun, view, sky, 5000, 12, 4).unwrap());
        let sum = o.single.value + o.multiple.value;
        assert!(
            (sum - o.total.value).abs() <= 1e-14 * o.total.value,
            "{o:?}"
        );
        assert!(o.multiple.value > 10.0 * o.multiple.se, "{o:?}");
    }
    // a flat plane scatters once: multiple exactly 0
    let flat = scene(&[0.0; 16], 4, 4, true, "lambertian", &[0.6]);
    let o = flat.brf_orders(sun, view, 0.0, 3000, 20, 1).unwrap();
    assert_eq!((o.multiple.value, o.multiple.se), (0.0, 0.0));
    assert!((o.single.value - 0.6).abs() < 1e-12, "{o:?}");
}

#[test]
fn orders_scale_as_powers_of_rho() {
    // Lambertian paths do not depend on rho (cosine sampling, weight rho):
    // order k carries exactly rho^k, so single / rho is the same for every
    // rho and multiple / rho^2 tends to the second-order term
    let z = rough(16, 5.0, 3);
    let (sun, view) = (dir(10.0, 40.0), dir(200.0, 25.0));
    let go = |rho: f64| {
        scene(&z, 16, 16, true, "lambertian", &[rho])
            .brf_orders(sun, view, 0.0, 4000, 30, 6)
            .unwrap()
    };
    let (a, b, c) = (go(1e-2), go(1e-3), go(1e-4));
    for (x, rho) in [(&a, 1e-2), (&b, 1e-3), (&c, 1e-4)] {
        let r1 = x.single.value / rho / (a.single.value / 1e-2);
        assert!((r1 - 1.0).abs() < 1e-12, "{rho}: {r1}");
    }
    let (m2, m3, m4) = (
        a.multiple.value / 1e-4,
        b.multiple.value / 1e-6,
        c.multiple.value / 1e-8,
    );
    assert!(m4 > 0.0 && m2 > m3 && m3 > m4, "{m2} {m3} {m4}");
    // the third-order remainder: relative 1e-3 then 1e-4 of the second order
    assert!(
        (m3 - m4) / m4 < 1e-2 && (m2 - m4) / m4 < 1e-1,
        "{m2} {m3} {m4}"
    );
}

#[test]
fn orders_of_a_conservative_v_groove() {
    // white V-grooves (rho = 1): the single-scattering nadir BRF is cos(s)
    // for every sun (closed form above), the rest is multiple scattering
    let s_deg: f64 = 30.0;
    let z = v_grooves(s_deg, 8);
    let sc = scene(&z, 8, 8, true, "lambertian", &[1.0]);
    for (az, zen) in [(90.0, 20.0), (0.0, 75.0)] {
        let o = sc
            .brf_orders(dir(az, zen), DVec3::Z, 0.0, 50_000, 200, 5)
            .unwrap();
        let expect = s_deg.to_radians().cos();
        assert!(
            (o.single.value - expect).abs() < 4.0 * o.single.se + 1e-9,
            "{o:?}"
        );
        assert!(o.multiple.value > 0.05, "{o:?}");
        let sum = o.single.value + o.multiple.value;
        assert!(
            (sum - o.total.value).abs() <= 1e-14 * o.total.value,
            "{o:?}"
        );
    }
}

#[test]
fn orders_do_not_depend_on_the_thread_count() {
    let z = rough(8, 4.0, 5);
    let s = scene(&z, 8, 8, true, "lambertian", &[0.4]);
    let go = |n| {
        run_in_pool(Some(n), || {
            s.brf_orders(dir(0.0, 30.0), dir(90.0, 10.0), 0.2, 5000, 4, 9)
        })
        .unwrap()
    };
    assert_eq!(go(1), go(2));
}
