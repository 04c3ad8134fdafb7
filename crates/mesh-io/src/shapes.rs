//! Meshes the project generates for tests and assets: closed, manifold, consistently
//! oriented (counter-clockwise seen from outside), with known topology.

use std::collections::HashMap;

use serde::{Deserialize, Serialize};

use crate::TriMesh;

/// A sphere (the boundary of a solid ball): the analytic reference surface of the sphere
/// study, shared by the training data and the metrics.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sphere {
    /// Centre.
    pub center: [f64; 3],
    /// Radius (> 0).
    pub radius: f64,
}

impl Sphere {
    /// Distance from `p` to the centre, `‖p − center‖` in f64.
    pub fn center_distance(&self, p: [f64; 3]) -> f64 {
        let d = [p[0] - self.center[0], p[1] - self.center[1], p[2] - self.center[2]];
        (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
    }

    /// Whether `p` is inside the closed ball (`‖p − center‖ ≤ radius`).
    pub fn contains(&self, p: [f64; 3]) -> bool {
        self.center_distance(p) <= self.radius
    }

    /// Signed distance from `p` to the sphere, `‖p − center‖ − radius`: negative inside,
    /// zero on the sphere, positive outside.
    pub fn distance(&self, p: [f64; 3]) -> f64 {
        self.center_distance(p) - self.radius
    }
}

/// The axis-aligned box from `lo` to `hi` (each coordinate of `lo` below `hi`'s): 8 vertices,
/// 12 triangles, genus 0.
pub fn cuboid(lo: [f64; 3], hi: [f64; 3]) -> TriMesh {
    let positions = (0..8).map(|i| [0, 1, 2].map(|k| if (i >> k) & 1 == 1 { hi[k] } else { lo[k] })).collect();
    let quads: [[u32; 4]; 6] = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let triangles = quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
    TriMesh { positions, triangles }
}

/// Unit-radius icosphere centred at the origin: the icosahedron with each triangle split
/// into four `subdivisions` times, new vertices projected onto the sphere.
/// 20·4^s triangles (s = 5 gives 20,480), genus 0.
pub fn icosphere(subdivisions: u32) -> TriMesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut positions: Vec<[f64; 3]> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|p| normalized(*p))
    .collect();
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut midpoint = |a: u32, b: u32, positions: &mut Vec<[f64; 3]>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (p, q) = (positions[a as usize], positions[b as usize]);
                positions.push(normalized([p[0] + q[0], p[1] + q[1], p[2] + q[2]]));
                positions.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(triangles.len() * 4);
        for [a, b, c] in triangles {
            let ab = midpoint(a, b, &mut positions);
            let bc = midpoint(b, c, &mut positions);
            let ca = midpoint(c, a, &mut positions);
            next.extend_from_slice(&[[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        triangles = next;
    }
    TriMesh { positions, triangles }
}

fn normalized(p: [f64; 3]) -> [f64; 3] {
    let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
    [p[0] / l, p[1] / l, p[2] / l]
}

/// Sweep a closed cross-section (`radial`, `axial` offsets, counter-clockwise in the
/// (radial, axial) plane) along a closed path of `n_major` directions in the XY plane.
/// Path points are `path_scale · (major + radial)` along each direction. Genus 1.
fn sweep(n_major: usize, angle0: f64, path_scale: f64, section: &[(f64, f64)], major: f64) -> TriMesh {
    let n_minor = section.len();
    let mut positions = Vec::with_capacity(n_major * n_minor);
    for i in 0..n_major {
        let th = angle0 + std::f64::consts::TAU * i as f64 / n_major as f64;
        let (s, c) = th.sin_cos();
        for &(r, z) in section {
            let rho = (major + r) * path_scale;
            positions.push([rho * c, rho * s, z]);
        }
    }
    let mut triangles = Vec::with_capacity(2 * n_major * n_minor);
    let id = |i: usize, j: usize| ((i % n_major) * n_minor + (j % n_minor)) as u32;
    for i in 0..n_major {
        for j in 0..n_minor {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    TriMesh { positions, triangles }
}

/// Torus around the Z axis: major radius `major`, minor radius `minor`, `n_major` × `n_minor`
/// quads split into triangles. Genus 1, volume → 2π²Rr² as the resolution grows.
pub fn torus(major: f64, minor: f64, n_major: usize, n_minor: usize) -> TriMesh {
    let section: Vec<(f64, f64)> = (0..n_minor)
        .map(|j| {
            let ph = std::f64::consts::TAU * j as f64 / n_minor as f64;
            (minor * ph.cos(), minor * ph.sin())
        })
        .collect();
    sweep(n_major, 0.0, 1.0, &section, major)
}

/// A box with a square hole through it (a square frame): outer half-width
/// `half_width + wall`, inner half-width `half_width - wall`, height `2·wall`, centred at
/// the origin. Sharp edges, flat faces, genus 1; exact volume from
/// [`box_with_hole_volume`].
pub fn box_with_hole(half_width: f64, wall: f64) -> TriMesh {
    // Square path through the diagonals: direction (cos 45°, sin 45°)·√2 reaches the
    // corner (1, 1), so radial offsets scale by √2 at each corner (mitred joints).
    let s2 = std::f64::consts::SQRT_2;
    let section = [(-wall, -wall), (wall, -wall), (wall, wall), (-wall, wall)];
    sweep(4, std::f64::consts::FRAC_PI_4, s2, &section, half_width)
}

/// Exact volume of [`box_with_hole`].
pub fn box_with_hole_volume(half_width: f64, wall: f64) -> f64 {
    let outer = 2.0 * (half_width + wall);
    let inner = 2.0 * (half_width - wall);
    2.0 * wall * (outer * outer - inner * inner)
}

/// The generated meshes shipped in `assets/`, by file stem.
pub fn asset_shapes() -> Vec<(&'static str, TriMesh)> {
    vec![("icosphere", icosphere(4)), ("torus", torus(1.0, 0.35, 64, 32)), ("box_with_hole", box_with_hole(1.0, 0.3))]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_signed_distance_and_containment() {
        let s = Sphere { center: [0.5, 0.5, 0.5], radius: 0.25 };
        assert_eq!(s.distance([0.5, 0.5, 0.5]), -0.25);
        assert_eq!(s.distance([1.0, 0.5, 0.5]), 0.25);
        assert_eq!(s.distance([0.5, 0.25, 0.5]), 0.0);
        assert!(s.contains([0.5, 0.25, 0.5]) && s.contains([0.6, 0.6, 0.6]));
        assert!(!s.contains([0.5, 0.5, 0.7500001]));
        // Containment agrees with the sign of the distance.
        for p in [[0.1, 0.2, 0.3], [0.7, 0.7, 0.7], [0.5, 0.5, 0.75], [0.3, 0.6, 0.4]] {
            assert_eq!(s.contains(p), s.distance(p) <= 0.0, "{p:?}");
        }
        let json = serde_json::to_string(&s).unwrap();
        assert_eq!(serde_json::from_str::<Sphere>(&json).unwrap(), s);
    }
}
