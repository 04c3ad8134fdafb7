//! Point-set generators shared by the integration tests, grouped by class, plus
//! independent brute-force checks.
#![allow(dead_code)]

use delaunay3::predicates::{in_conflict_finite, orient};
use delaunay3::Delaunay3;

/// Deterministic SplitMix64.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n
    }
}

/// #n×3 uniform in the unit cube.
pub fn uniform(n: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut r = Rng(seed);
    (0..n).map(|_| [r.unit(), r.unit(), r.unit()]).collect()
}

/// The k×k×k integer lattice.
pub fn lattice(k: usize) -> Vec<[f64; 3]> {
    let mut v = Vec::with_capacity(k * k * k);
    for x in 0..k {
        for y in 0..k {
            for z in 0..k {
                v.push([x as f64, y as f64, z as f64]);
            }
        }
    }
    v
}

/// All integer solutions of x² + y² + z² = r2, sorted lexicographically.
pub fn sphere_integer_solutions(r2: i64) -> Vec<[i64; 3]> {
    let r = (r2 as f64).sqrt() as i64 + 1;
    let mut out = Vec::new();
    for x in -r..=r {
        let rx = r2 - x * x;
        if rx < 0 {
            continue;
        }
        let ry = (rx as f64).sqrt() as i64 + 1;
        for y in -ry..=ry {
            let rz = rx - y * y;
            if rz < 0 {
                continue;
            }
            let mut z = (rz as f64).sqrt() as i64;
            while z * z > rz {
                z -= 1;
            }
            while (z + 1) * (z + 1) <= rz {
                z += 1;
            }
            if z * z == rz {
                out.push([x, y, z]);
                if z != 0 {
                    out.push([x, y, -z]);
                }
            }
        }
    }
    out.sort_unstable();
    out
}

/// `count` integer points exactly on the sphere x² + y² + z² = r2, chosen
/// deterministically (seeded partial Fisher–Yates over the sorted solutions).
pub fn cospherical(r2: i64, count: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut sols = sphere_integer_solutions(r2);
    assert!(sols.len() >= count, "only {} solutions", sols.len());
    let mut r = Rng(seed);
    for i in 0..count {
        let j = i + r.below((sols.len() - i) as u64) as usize;
        sols.swap(i, j);
    }
    sols[..count]
        .iter()
        .map(|p| {
            assert_eq!(p[0] * p[0] + p[1] * p[1] + p[2] * p[2], r2);
            [p[0] as f64, p[1] as f64, p[2] as f64]
        })
        .collect()
}

/// Points on `num_planes` axis-parallel and oblique planes (integer coordinates so
/// the coplanarity is exact), plus a few points off the planes.
pub fn planes(per_plane: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut r = Rng(seed);
    let mut v = Vec::new();
    for i in 0..per_plane {
        let (a, b) = (r.below(1000) as f64, r.below(1000) as f64);
        v.push([a, b, 0.0]); // z = 0
        v.push([a, b, 500.0]); // z = 500, same (x, y): vertical cospherical groups
        v.push([0.0, a, b]); // x = 0
        v.push([a, a, b]); // x = y (oblique)
        let c = r.below(1000) as f64;
        v.push([a, b, 1000.0 - a - b + 0.0 * c]); // x + y + z = 1000
        if i % 10 == 0 {
            v.push([r.unit() * 1000.0, r.unit() * 1000.0, r.unit() * 1000.0]);
        }
    }
    v
}

/// Clusters whose spacing shrinks geometrically: cluster k has points at scale 2^-3k
/// around a centre, for k = 0..levels.
pub fn exponential_clusters(per_cluster: usize, levels: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut r = Rng(seed);
    let mut v = Vec::new();
    for k in 0..levels {
        let s = (2.0f64).powi(-3 * k as i32);
        let c = [0.5 + 0.3 * r.unit(), 0.5, 0.5 - 0.2 * r.unit()];
        for _ in 0..per_cluster {
            v.push([c[0] + s * (r.unit() - 0.5), c[1] + s * (r.unit() - 0.5), c[2] + s * (r.unit() - 0.5)]);
        }
        // A geometric sequence along a line as well.
        v.push([0.1 + s, 0.2 + 0.5 * s, 0.3]);
    }
    v
}

/// `base` with every point repeated `copies` extra times, shuffled deterministically.
pub fn with_duplicates(base: &[[f64; 3]], copies: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut v: Vec<[f64; 3]> = Vec::new();
    for _ in 0..=copies {
        v.extend_from_slice(base);
    }
    let mut r = Rng(seed);
    for i in (1..v.len()).rev() {
        let j = r.below(i as u64 + 1) as usize;
        v.swap(i, j);
    }
    v
}

/// Every coordinate times `s` (rounded; the result is a different but nearby set).
pub fn scaled(points: &[[f64; 3]], s: f64) -> Vec<[f64; 3]> {
    points.iter().map(|p| p.map(|x| x * s)).collect()
}

/// Build, validate, and check the duplicate maps against the input; returns the
/// triangulation.
pub fn build_and_check(points: &[[f64; 3]]) -> Delaunay3 {
    let dt = Delaunay3::new(points).expect("triangulation");
    dt.validate().expect("validate");
    assert_eq!(dt.num_inputs(), points.len());
    for (i, p) in points.iter().enumerate() {
        let v = dt.vertex_of_input(i);
        let q = dt.vertex(v);
        assert!(q.iter().zip(p).all(|(a, b)| a == b), "input {i} {p:?} mapped to vertex {v} at {q:?}");
        assert!(dt.input_of_vertex(v) as usize <= i);
    }
    dt
}

/// Independent O(V·M) global check: no vertex is inside any finite tetrahedron's
/// perturbed circumsphere, every finite tetrahedron is positively oriented. Uses the
/// vertex coordinates as given, so only for inputs not rescaled internally.
pub fn brute_force_delaunay(dt: &Delaunay3) {
    assert_eq!(dt.scale_exponent(), 0, "brute force needs unscaled inputs");
    let pts: Vec<[f64; 3]> = (0..dt.num_vertices() as u32).map(|v| dt.vertex(v)).collect();
    for (t, tet) in dt.finite_tets().enumerate() {
        let [a, b, c, d] = tet.map(|v| &pts[v as usize]);
        assert_eq!(orient(a, b, c, d), 1, "tet {t} {tet:?} not positive");
        for (v, p) in pts.iter().enumerate() {
            if tet.contains(&(v as u32)) {
                continue;
            }
            assert!(!in_conflict_finite([a, b, c, d], p), "vertex {v} inside the circumsphere of tet {t} {tet:?}");
        }
    }
}

/// The finite tetrahedra as sorted coordinate quadruples (an order-independent key).
pub fn tet_set_by_coords(dt: &Delaunay3) -> Vec<[[u64; 3]; 4]> {
    let mut v: Vec<[[u64; 3]; 4]> = dt
        .finite_tets()
        .map(|t| {
            let mut q = t.map(|v| dt.vertex(v).map(f64::to_bits));
            q.sort_unstable();
            q
        })
        .collect();
    v.sort_unstable();
    v
}
