//! Hausdorff distances: the libigl-compatible value against brute force, the certified
//! interval against analytic values and dense sampling, errors, determinism.

mod common;

use mesh_io::shapes::{box_with_hole, icosphere, torus};
use mesh_io::TriMesh;
use metrics::{
    directed_hausdorff_certified, hausdorff_certified, hausdorff_libigl, CertifiedOptions, HausdorffInterval,
    MetricsError,
};

fn certified(a: &TriMesh, b: &TriMesh) -> HausdorffInterval {
    hausdorff_certified(a, b, &CertifiedOptions::default()).unwrap()
}

/// The interval is ordered, converged and no wider than asked.
fn assert_tight(r: &HausdorffInterval, what: &str) {
    assert!(r.converged, "{what}: not converged: {r:?}");
    assert!(r.lo <= r.hi, "{what}: {r:?}");
    assert!(r.hi - r.lo <= 1e-6 * r.diagonal, "{what}: width {} > 1e-6 x {}", r.hi - r.lo, r.diagonal);
    assert!(r.lo <= r.witness && r.witness <= r.hi, "{what}: witness outside: {r:?}");
}

fn assert_contains(r: &HausdorffInterval, value: f64, what: &str) {
    assert!(r.lo <= value && value <= r.hi, "{what}: {value} not in [{}, {}]", r.lo, r.hi);
}

#[test]
fn libigl_value_equals_brute_force_vertex_maximum() {
    let pairs = [
        (icosphere(2), common::translated(&icosphere(1), [0.1, 0.05, -0.02])),
        (torus(1.0, 0.3, 24, 12), common::scaled(&torus(1.0, 0.3, 16, 8), 1.05)),
        (box_with_hole(1.0, 0.3), icosphere(2)),
    ];
    for (i, (a, b)) in pairs.iter().enumerate() {
        let ab = a.positions.iter().map(|p| common::brute_d2(*p, b)).fold(0.0, f64::max);
        let ba = b.positions.iter().map(|p| common::brute_d2(*p, a)).fold(0.0, f64::max);
        let want = ab.max(ba).sqrt();
        assert_eq!(hausdorff_libigl(a, b).unwrap(), want, "pair {i}");
    }
}

#[test]
fn libigl_value_counts_unreferenced_vertices_like_libigl() {
    // igl.hausdorff measures from every row of V: a stray vertex dominates.
    let a = TriMesh {
        positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [5.0, 5.0, 5.0]],
        triangles: vec![[0, 1, 2]],
    };
    let b = common::translated(
        &TriMesh { positions: a.positions[..3].to_vec(), triangles: a.triangles.clone() },
        [0.0, 0.0, 0.1],
    );
    // igl.hausdorff gives 8.031811750782012 on this pair (libigl 2.6.3).
    assert!((hausdorff_libigl(&a, &b).unwrap() - 8.031811750782012).abs() < 1e-12);
    // The surfaces themselves are 0.1 apart.
    let r = certified(&a, &b);
    assert_tight(&r, "stray vertex");
    assert_contains(&r, 0.1, "stray vertex");
}

#[test]
fn scaled_icosphere_equals_analytic_value() {
    // B = s·A with A inscribed in the unit sphere: H = s − 1, attained at B's vertices.
    for (sub, s) in [(0, 1.5), (3, 1.25), (4, 0.9)] {
        let a = icosphere(sub);
        let b = common::scaled(&a, s);
        let r = certified(&a, &b);
        assert_tight(&r, "scaled icosphere");
        let want = (s - 1.0f64).abs();
        assert_contains(&r, want, &format!("icosphere({sub}) scaled by {s}"));
    }
}

#[test]
fn translated_icosphere_equals_analytic_value() {
    // H(A, A + t) = |t| for a convex polyhedron (the vertex extreme in direction −t).
    let a = icosphere(2);
    let t = [0.3, -0.2, 0.1];
    let r = certified(&a, &common::translated(&a, t));
    assert_tight(&r, "translated icosphere");
    assert_contains(&r, (0.09f64 + 0.04 + 0.01).sqrt(), "translated icosphere");
}

/// Icosahedron (unit circumradius) against its first subdivision (midpoints pushed onto
/// the sphere). With φ the golden ratio and `R = sqrt(1 + φ²)`:
/// - an edge midpoint has norm `|m| = φ / R` and the faces' inradius is `ρ = φ² / (√3 R)`;
/// - `h(B, A) = 1 − |m|` (the pushed midpoints are B's farthest points from A), which is
///   the symmetric distance;
/// - `h(A, B) = ρ / |m| − ρ`: inside the convex B, the distance to ∂B is the smallest
///   distance to a face plane, a concave function maximal at a face centre by symmetry,
///   where the nearest plane is the parallel central sub-face at distance `ρ / |m|` from
///   the origin. This one is attained inside a face of A, far from any vertex.
#[test]
fn icosahedron_against_its_subdivision_equals_analytic_values() {
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let big_r = (1.0 + phi * phi).sqrt();
    let m = phi / big_r;
    let rho = phi * phi / (3f64.sqrt() * big_r);
    let (a, b) = (icosphere(0), icosphere(1));

    let r = certified(&a, &b);
    assert_tight(&r, "symmetric");
    assert_contains(&r, 1.0 - m, "symmetric");

    let d = directed_hausdorff_certified(&a, &b, &CertifiedOptions::default()).unwrap();
    assert_tight(&d, "directed");
    let want = rho / m - rho;
    assert_contains(&d, want, "directed A -> B");
    // Every vertex of A is also a vertex of B: the vertex-only value of this direction is 0.
    assert_eq!(d.directed_witness[1], 0.0);
    assert!(want > 0.13);
}

#[test]
fn decimated_bunny_interval_contains_dense_sampling_maximum() {
    let bunny = common::bunny();
    let coarse = common::cluster_decimate(&bunny, 14);
    assert!(coarse.triangles.len() < bunny.triangles.len() / 2, "{} faces", coarse.triangles.len());
    let libigl = hausdorff_libigl(&bunny, &coarse).unwrap();
    let r = certified(&bunny, &coarse);
    assert_tight(&r, "bunny");
    let dense = common::dense_max(&bunny, &coarse, 400_000, 1).max(common::dense_max(&coarse, &bunny, 400_000, 2));
    // Dense sampling is a lower bound that approaches the true value from below: it never
    // exceeds hi, and 800,000 samples get within 1% of lo.
    assert!(dense <= r.hi && dense >= 0.99 * r.lo, "dense {dense} vs [{}, {}]", r.lo, r.hi);
    // The witness is a real point: brute force over the other mesh gives its distance.
    let other = if r.witness_direction == 0 { &coarse } else { &bunny };
    let brute = common::brute_d2(r.witness_point, other).sqrt();
    assert!((brute - r.witness).abs() <= r.rounding_margin, "{brute} vs {}", r.witness);
    // The vertex-only value is too low here (every coarse vertex lies on the bunny).
    assert!(libigl < r.lo && libigl < dense, "libigl {libigl} vs certified {} and dense {dense}", r.lo);
    assert!(r.witness >= libigl - r.tolerance, "witness {} < libigl {libigl}", r.witness);
    let all =
        hausdorff_certified(&bunny, &coarse, &CertifiedOptions { all_vertices: true, ..Default::default() }).unwrap();
    assert_eq!(all.libigl, Some(libigl));
    assert!(all.witness >= libigl && dense <= all.hi);
    assert_eq!(all.lo, r.lo);
}

#[test]
fn identical_and_overlapping_meshes_give_zero() {
    let a = torus(1.0, 0.35, 32, 16);
    let r = certified(&a, &a);
    // Vertices are exactly on the other mesh; edge midpoints within rounding.
    assert!(r.witness <= r.rounding_margin && r.lo == 0.0, "{r:?}");
    assert!(r.hi <= 1e-6 * r.diagonal, "{r:?}");
    // A mesh and a copy with its triangles listed twice and reversed.
    let mut b = a.clone();
    b.triangles.extend(a.triangles.iter().map(|t| [t[0], t[2], t[1]]));
    let r = certified(&a, &b);
    assert!(r.witness <= r.rounding_margin && r.lo == 0.0, "{r:?}");
}

#[test]
fn degenerate_triangles_are_part_of_the_surface() {
    // A: a unit triangle plus a needle (collinear) and a point triangle far away.
    let a = TriMesh {
        positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 2.0], [0.0, 0.0, 3.0]],
        triangles: vec![[0, 1, 2], [0, 3, 4], [4, 4, 4]],
    };
    let b = TriMesh { positions: a.positions[..3].to_vec(), triangles: vec![[0, 1, 2]] };
    let r = certified(&a, &b);
    assert_tight(&r, "degenerate");
    assert_contains(&r, 3.0, "degenerate");
    // All-degenerate on both sides: segments.
    let s1 = TriMesh { positions: vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]], triangles: vec![[0, 1, 2]] };
    let s2 = common::translated(&s1, [0.0, 0.5, 0.0]);
    let r = certified(&s1, &s2);
    assert_tight(&r, "segments");
    assert_contains(&r, 0.5, "segments");
}

#[test]
fn bad_meshes_are_errors_not_panics() {
    let good = icosphere(1);
    let empty = TriMesh::default();
    let no_tris = TriMesh { positions: vec![[0.0; 3]], triangles: vec![] };
    let nan =
        TriMesh { positions: vec![[f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], triangles: vec![[0, 1, 2]] };
    let inf = TriMesh {
        positions: vec![[0.0, 0.0, f64::INFINITY], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        triangles: vec![[0, 1, 2]],
    };
    let huge =
        TriMesh { positions: vec![[1e200, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], triangles: vec![[0, 1, 2]] };
    let oob = TriMesh { positions: vec![[0.0; 3], [1.0, 0.0, 0.0]], triangles: vec![[0, 1, 7]] };
    let opts = CertifiedOptions::default();
    assert!(matches!(hausdorff_certified(&empty, &good, &opts), Err(MetricsError::Empty { mesh: "A" })));
    assert!(matches!(hausdorff_certified(&good, &no_tris, &opts), Err(MetricsError::Empty { mesh: "B" })));
    assert!(matches!(hausdorff_certified(&nan, &good, &opts), Err(MetricsError::BadVertex { vertex: 0, .. })));
    assert!(matches!(hausdorff_libigl(&good, &inf), Err(MetricsError::BadVertex { mesh: "B", .. })));
    assert!(matches!(hausdorff_libigl(&huge, &good), Err(MetricsError::BadVertex { .. })));
    assert!(matches!(
        hausdorff_libigl(&good, &oob),
        Err(MetricsError::VertexOutOfRange { mesh: "B", triangle: 0, vertex: 7, num_vertices: 2 })
    ));
    for bad in [
        CertifiedOptions { rel_tolerance: 0.0, ..Default::default() },
        CertifiedOptions { rel_tolerance: f64::NAN, ..Default::default() },
        CertifiedOptions { max_depth: 0, ..Default::default() },
        CertifiedOptions { max_depth: 60, ..Default::default() },
        CertifiedOptions { max_active_cells: 0, ..Default::default() },
    ] {
        assert!(matches!(hausdorff_certified(&good, &good, &bad), Err(MetricsError::BadOption(_))), "{bad:?}");
    }
    // Messages name the mesh and say what to do.
    let msg = hausdorff_certified(&nan, &good, &opts).unwrap_err().to_string();
    assert!(msg.contains("vertex 0 of the A mesh") && msg.contains("repair"), "{msg}");
}

#[test]
fn limits_give_a_valid_wider_interval() {
    let bunny = common::bunny();
    let coarse = common::cluster_decimate(&bunny, 10);
    let full = certified(&bunny, &coarse);
    let cut = hausdorff_certified(&bunny, &coarse, &CertifiedOptions { max_depth: 1, ..Default::default() }).unwrap();
    assert!(!cut.converged);
    assert!(cut.lo <= full.hi && full.lo <= cut.hi, "{cut:?} vs {full:?}");
    assert!(cut.hi >= full.hi - 1e-12);
    let loose =
        hausdorff_certified(&bunny, &coarse, &CertifiedOptions { rel_tolerance: 1e-2, ..Default::default() }).unwrap();
    assert!(loose.converged && loose.hi - loose.lo <= 1e-2 * loose.diagonal);
    assert!(loose.lo <= full.hi && full.lo <= loose.hi);
}

#[test]
fn result_does_not_depend_on_thread_count() {
    let bunny = common::bunny();
    let coarse = common::cluster_decimate(&bunny, 12);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        let mut r = pool.install(|| certified(&bunny, &coarse));
        r.seconds = 0.0;
        r
    };
    let one = run(1);
    assert_eq!(one, run(2));
    assert_eq!(one, run(3));
}

/// Random triangle soups (some nearly degenerate, some far apart): the interval always
/// contains what dense sampling and a barycentric grid see from below, and stays tight.
#[test]
fn random_soups_interval_is_never_below_dense_sampling() {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut rnd = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for case in 0..60 {
        let mut soup = |n: usize, spread: f64, offset: f64| {
            let mut m = TriMesh::default();
            for i in 0..n {
                let c = [rnd() * spread + offset, rnd() * spread, rnd() * spread];
                let size = if i % 7 == 0 { 1e-4 } else { 0.3 };
                for _ in 0..3 {
                    m.positions.push([c[0] + size * rnd(), c[1] + size * rnd(), c[2] + size * rnd()]);
                }
                let v = 3 * i as u32;
                m.triangles.push([v, v + 1, v + 2]);
            }
            m
        };
        let a = soup(1 + case % 17, 1.0, 0.0);
        let b = soup(1 + (case * 7) % 23, 1.0 + (case % 3) as f64, 0.2 * (case % 5) as f64);
        let r = certified(&a, &b);
        assert_tight(&r, &format!("case {case}"));
        let mut seen = common::dense_max(&a, &b, 20_000, case as u64).max(common::dense_max(&b, &a, 20_000, 99));
        // Barycentric grid including edges and corners.
        for (src, tgt) in [(&a, &b), (&b, &a)] {
            for t in &src.triangles {
                let [p, q, s] = t.map(|v| src.positions[v as usize]);
                let n = 12;
                for i in 0..=n {
                    for j in 0..=(n - i) {
                        let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                        let x = [0, 1, 2].map(|k| p[k] + u * (q[k] - p[k]) + v * (s[k] - p[k]));
                        seen = seen.max(common::brute_d2(x, tgt).sqrt());
                    }
                }
            }
        }
        assert!(seen <= r.hi, "case {case}: sampled {seen} above hi {}", r.hi);
        assert!(seen >= r.lo - 0.05 * r.diagonal, "case {case}: sampled {seen} far below lo {}", r.lo);
    }
}
