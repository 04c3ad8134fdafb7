//! `crust::prune`: the sites it removes change neither the crust nor the nearest-site
//! occupancy, on random sites, on mirrored pairs (degenerate by construction) with a
//! lattice of sites inside and out (cospherical everywhere), on the same rounded to f32,
//! and with coincident sites; and removing a site it keeps does change the crust.

use std::f64::consts::PI;

use crust::prune::{prune, removable};
use crust::{Crust, CrustConfig};
use mesh_io::{TopologyReport, TriMesh};

fn rng(seed: u64) -> impl FnMut() -> f64 {
    let mut s = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
    move || {
        s ^= s >> 12;
        s ^= s << 25;
        s ^= s >> 27;
        ((s.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
}

fn in_ball(p: [f64; 3]) -> bool {
    (0..3).map(|k| (p[k] - 0.5).powi(2)).sum::<f64>() < 0.3 * 0.3
}

/// Uniform random sites labelled by a ball.
fn random_ball(n: usize) -> (Vec<[f64; 3]>, Vec<bool>) {
    let mut r = rng(7);
    let sites: Vec<[f64; 3]> = (0..n).map(|_| [r(), r(), r()]).collect();
    let inside = sites.iter().map(|&p| in_ball(p)).collect();
    (sites, inside)
}

/// Mirrored pairs c + (0.3 ± δ)n on a Fibonacci lattice, with a regular lattice of sites
/// inside and outside the sphere away from it (cospherical in every cube of the lattice)
/// and a grid on each face of the box, as the main job's boundary sites; optionally
/// rounded to f32.
fn pairs_and_lattice(pairs: usize, f32_round: bool) -> (Vec<[f64; 3]>, Vec<bool>) {
    let golden = PI * (3.0 - 5f64.sqrt());
    let spacing = 0.3 * (4.0 * PI / pairs as f64).sqrt();
    let delta = 0.3 * spacing;
    let mut sites = Vec::new();
    let mut inside = Vec::new();
    for i in 0..pairs {
        let z = 1.0 - (2.0 * i as f64 + 1.0) / pairs as f64;
        let rho = (1.0 - z * z).sqrt();
        let phi = golden * i as f64;
        let n = [rho * phi.cos(), rho * phi.sin(), z];
        for (s, label) in [(-1.0, true), (1.0, false)] {
            sites.push([0, 1, 2].map(|k| 0.5 + (0.3 + s * delta) * n[k]));
            inside.push(label);
        }
    }
    let m = 12;
    for i in 0..m {
        for j in 0..m {
            for k in 0..m {
                let p = [i, j, k].map(|a| (a as f64 + 0.5) / m as f64);
                let r = (0..3).map(|a| (p[a] - 0.5).powi(2)).sum::<f64>().sqrt();
                if (r - 0.3).abs() > 2.0 * spacing {
                    sites.push(p);
                    inside.push(r < 0.3);
                }
            }
        }
    }
    let g = 8;
    for axis in 0..3 {
        for face in [1e-3, 1.0 - 1e-3] {
            for i in 0..g {
                for j in 0..g {
                    let mut p = [face; 3];
                    p[(axis + 1) % 3] = (i as f64 + 0.5) / g as f64;
                    p[(axis + 2) % 3] = (j as f64 + 0.5) / g as f64;
                    sites.push(p);
                    inside.push(false);
                }
            }
        }
    }
    if f32_round {
        for p in &mut sites {
            *p = p.map(|x| x as f32 as f64);
        }
    }
    (sites, inside)
}

/// Label of the nearest site (ties to the lower index), brute force.
fn occupancy(sites: &[[f64; 3]], inside: &[bool], x: [f64; 3]) -> bool {
    let d2 = |p: &[f64; 3]| (0..3).map(|k| (p[k] - x[k]).powi(2)).sum::<f64>();
    let mut best = (f64::INFINITY, false);
    for (p, &l) in sites.iter().zip(inside) {
        let d = d2(p);
        if d < best.0 {
            best = (d, l);
        }
    }
    best.1
}

/// The crust mesh, its Voronoi faces (polygons), volume and area.
fn measure(sites: &[[f64; 3]], inside: &[bool]) -> (TriMesh, usize, f64, f64) {
    let c = Crust::extract(sites, inside, &CrustConfig::default()).expect("crust");
    let area = c
        .mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, d] = t.map(|i| c.mesh.positions[i as usize]);
            let (u, w) = ([0, 1, 2].map(|k| b[k] - a[k]), [0, 1, 2].map(|k| d[k] - a[k]));
            let n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]];
            0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt()
        })
        .sum();
    (c.mesh.clone(), c.stats.num_polygons, TopologyReport::of(&c.mesh).signed_volume, area)
}

/// The largest distance from a vertex or a triangle centroid of `a` to the surface of `b`
/// (brute force over `b`'s triangles).
fn far_from(a: &TriMesh, b: &TriMesh) -> f64 {
    let tris: Vec<[[f64; 3]; 3]> = b.triangles.iter().map(|t| t.map(|i| b.positions[i as usize])).collect();
    let centroids = a.triangles.iter().map(|t| {
        let [p, q, r] = t.map(|i| a.positions[i as usize]);
        [0, 1, 2].map(|k| (p[k] + q[k] + r[k]) / 3.0)
    });
    a.positions
        .iter()
        .copied()
        .chain(centroids)
        .map(|x| tris.iter().map(|t| point_triangle(x, t)).fold(f64::INFINITY, f64::min))
        .fold(0.0, f64::max)
}

/// Distance from `p` to triangle `t` (Ericson, Real-Time Collision Detection, 5.1.5).
fn point_triangle(p: [f64; 3], t: &[[f64; 3]; 3]) -> f64 {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let at = |o: [f64; 3], d: [f64; 3], s: f64| [o[0] + s * d[0], o[1] + s * d[1], o[2] + s * d[2]];
    let [a, b, c] = *t;
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    let q = if d1 <= 0.0 && d2 <= 0.0 {
        a
    } else {
        let bp = sub(p, b);
        let (d3, d4) = (dot(ab, bp), dot(ac, bp));
        let cp = sub(p, c);
        let (d5, d6) = (dot(ab, cp), dot(ac, cp));
        let (vc, vb, va) = (d1 * d4 - d3 * d2, d5 * d2 - d1 * d6, d3 * d6 - d5 * d4);
        if d3 >= 0.0 && d4 <= d3 {
            b
        } else if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
            at(a, ab, d1 / (d1 - d3))
        } else if d6 >= 0.0 && d5 <= d6 {
            c
        } else if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
            at(a, ac, d2 / (d2 - d6))
        } else if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
            at(b, sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6)))
        } else {
            let denom = 1.0 / (va + vb + vc);
            let (v, w) = (vb * denom, vc * denom);
            [0, 1, 2].map(|k| a[k] + ab[k] * v + ac[k] * w)
        }
    };
    dot(sub(p, q), sub(p, q)).sqrt()
}

/// Prunes to the end and checks the crust and the occupancy did not change.
fn check_unchanged(what: &str, sites: Vec<[f64; 3]>, inside: Vec<bool>) -> usize {
    let (v0, t0, vol0, area0) = measure(&sites, &inside);
    let (mut s, mut l) = (sites.clone(), inside.clone());
    let report = prune(&mut s, &mut l, 0, 64, &CrustConfig::default()).expect("prune");
    let removed = report.removed();
    assert_eq!(s.len(), sites.len() - removed, "{what}");
    assert!(removed > sites.len() / 20, "{what}: only {removed} of {} removed", sites.len());
    // Converged: nothing left to remove.
    assert!(removable(&s, &l, &[], &CrustConfig::default()).unwrap().iter().all(|&g| !g), "{what}");
    // The same crust: as many Voronoi faces, each surface on the other, the same volume and
    // area. Not the same vertices: where sites are exactly degenerate, as mirrored pairs
    // can be, four cells meet along a segment rather than at a point and the
    // tetrahedralization's perturbation picks which end is a vertex (on the f64 pairs
    // here, vertices 0.015 apart on the same surface). The surfaces agree to within the
    // rounding of nearly flat tetrahedra's circumcentres and of this test's own distance
    // to sliver triangles (2e-11 on random sites, 5e-8 on the f32 pairs), far below the
    // site spacing (0.04) that any real change would show at.
    let (v1, t1, vol1, area1) = measure(&s, &l);
    assert_eq!(t0, t1, "{what}: Voronoi faces in the crust");
    let worst = far_from(&v0, &v1).max(far_from(&v1, &v0));
    assert!(worst < 1e-6, "{what}: a point of one crust {worst} from the other");
    assert!((vol0 - vol1).abs() <= 1e-12 * vol0.abs(), "{what}: volume {vol0} -> {vol1}");
    assert!((area0 - area1).abs() <= 1e-12 * area0, "{what}: area {area0} -> {area1}");
    // The same occupancy at random points and next to every crust vertex.
    let mut r = rng(11);
    let mut points: Vec<[f64; 3]> = (0..4000).map(|_| [r(), r(), r()]).collect();
    points.extend(v0.positions.iter().step_by(7).map(|p| p.map(|x| (x + 2e-3 * (r() - 0.5)).clamp(0.0, 1.0))));
    for x in points {
        assert_eq!(occupancy(&sites, &inside, x), occupancy(&s, &l, x), "{what}: occupancy at {x:?}");
    }
    removed
}

#[test]
fn random_sites_keep_their_crust_and_occupancy() {
    let (s, l) = random_ball(3000);
    check_unchanged("random ball", s, l);
}

#[test]
fn mirrored_pairs_with_a_lattice_keep_their_crust_and_occupancy() {
    let (s, l) = pairs_and_lattice(600, false);
    let n = s.len();
    let removed = check_unchanged("pairs + lattice", s, l);
    // The lattice far from the sphere and the face grids are nearly all redundant.
    assert!(removed > n / 4, "{removed} of {n}");
}

#[test]
fn rounded_to_f32_keeps_its_crust_and_occupancy() {
    let (s, l) = pairs_and_lattice(600, true);
    check_unchanged("pairs + lattice, f32", s, l);
}

#[test]
fn coincident_sites_are_kept() {
    let (mut s, mut l) = random_ball(1500);
    // Copies of 50 sites, some with the other label.
    for i in 0..50 {
        s.push(s[i * 7]);
        l.push(if i % 2 == 0 { l[i * 7] } else { !l[i * 7] });
    }
    let gone = removable(&s, &l, &[], &CrustConfig::default()).unwrap();
    for i in 0..50 {
        assert!(!gone[i * 7] && !gone[1500 + i], "coincident site {} chosen", i * 7);
    }
    let before = measure(&s, &l);
    let (mut s2, mut l2) = (s.clone(), l.clone());
    prune(&mut s2, &mut l2, 0, 64, &CrustConfig::default()).unwrap();
    let after = measure(&s2, &l2);
    assert_eq!(before.1, after.1);
    assert!(far_from(&before.0, &after.0).max(far_from(&after.0, &before.0)) < 1e-6);
    assert!((before.2 - after.2).abs() <= 1e-12 * before.2.abs());
}

#[test]
fn kept_prefix_and_independence() {
    let (s, l) = random_ball(2000);
    let cfg = CrustConfig::default();
    // Nothing below `keep_below` goes.
    let (mut a, mut b) = (s.clone(), l.clone());
    assert_eq!(prune(&mut a, &mut b, s.len(), 64, &cfg).unwrap().removed(), 0);
    assert_eq!(a, s);
    let (mut a, mut b) = (s.clone(), l.clone());
    prune(&mut a, &mut b, 1000, 64, &cfg).unwrap();
    assert_eq!(a[..1000], s[..1000]);
    // One round's choice is an independent set of the tetrahedralization's edge graph.
    let gone = removable(&s, &l, &[], &cfg).unwrap();
    let dt = delaunay3::Delaunay3::new(&s).unwrap();
    for e in dt.edges() {
        let [p, q] = e.vertices.map(|v| dt.input_of_vertex(v) as usize);
        assert!(!(gone[p] && gone[q]), "neighbours {p} and {q} both chosen");
        if gone[p] || gone[q] {
            assert_eq!(l[p], l[q], "a chosen site has a neighbour with the other label");
        }
    }
}

#[test]
fn removing_a_site_it_keeps_changes_the_crust() {
    // The check above can fail: a site with a neighbour of the other label is not
    // redundant, and removing it changes the crust.
    let (s, l) = random_ball(2000);
    let gone = removable(&s, &l, &[], &CrustConfig::default()).unwrap();
    let dt = delaunay3::Delaunay3::new(&s).unwrap();
    let mixed = dt
        .edges()
        .iter()
        .map(|e| e.vertices.map(|v| dt.input_of_vertex(v) as usize))
        .find(|&[p, q]| l[p] != l[q])
        .unwrap()[0];
    assert!(!gone[mixed]);
    let (v0, t0, vol0, _) = measure(&s, &l);
    let (mut s2, mut l2) = (s.clone(), l.clone());
    s2.remove(mixed);
    l2.remove(mixed);
    let (v1, t1, vol1, _) = measure(&s2, &l2);
    assert!(t0 != t1 || far_from(&v0, &v1).max(far_from(&v1, &v0)) > 1e-6 || (vol0 - vol1).abs() > 1e-12 * vol0.abs());
}
