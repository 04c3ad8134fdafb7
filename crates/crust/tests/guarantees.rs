//! The crust's guarantees on a corpus of generated cases: closed, oppositely oriented
//! edges, vertex-manifold, free of self-intersections (exact), volume equal to the summed
//! volume of the inside cells (1e-9 relative), every cell a closed convex polyhedron.

use crust::check::check_crust;
use crust::{Crust, CrustConfig};
use mesh_io::TopologyReport;
use proptest::prelude::*;

/// xorshift64*: a tiny deterministic generator for test inputs.
struct Rng(u64);
impl Rng {
    fn f(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in the open unit interval.
    fn open(&mut self) -> f64 {
        loop {
            let x = self.f();
            if x > 0.0 {
                return x;
            }
        }
    }
}

/// Extract, check every guarantee, return the crust.
fn check(sites: &[[f64; 3]], inside: &[bool], what: &str) -> Crust {
    let mut crust = Crust::extract(sites, inside, &CrustConfig::default()).unwrap_or_else(|e| panic!("{what}: {e}"));
    let c = check_crust(&crust.mesh).unwrap_or_else(|e| panic!("{what}: {e}"));
    let cells = crust.cells().unwrap();
    let mut cell_volume = 0.0;
    for (site, cell) in &cells {
        assert!(inside[*site], "{what}: cell of an outside site");
        let r = TopologyReport::of(cell);
        assert!(
            r.is_closed && r.is_orientation_consistent && r.genus == Some(0),
            "{what}: cell of site {site} is not a closed sphere: {r:?}"
        );
        assert!(r.signed_volume > 0.0, "{what}: cell {site} volume {}", r.signed_volume);
        // Inside the box (up to the rounding of mirror sites).
        assert!(
            cell.positions.iter().flatten().all(|&x| (-1e-12..=1.0 + 1e-12).contains(&x)),
            "{what}: cell {site} leaves the box"
        );
        cell_volume += r.signed_volume;
    }
    let crust_volume = c.report.signed_volume;
    if crust.mesh.triangles.is_empty() {
        assert!(cells.is_empty() || inside.iter().all(|&b| !b), "{what}");
    } else {
        assert!(
            (crust_volume - cell_volume).abs() <= 1e-9 * cell_volume,
            "{what}: crust volume {crust_volume} vs cells {cell_volume}"
        );
    }
    crust
}

fn uniform(rng: &mut Rng, k: usize) -> Vec<[f64; 3]> {
    (0..k).map(|_| [rng.open(), rng.open(), rng.open()]).collect()
}

fn lattice(n: usize) -> Vec<[f64; 3]> {
    let mut v = Vec::new();
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                v.push([(i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64, (k as f64 + 0.5) / n as f64]);
            }
        }
    }
    v
}

fn ball(sites: &[[f64; 3]], r: f64) -> Vec<bool> {
    sites.iter().map(|p| (p[0] - 0.5).powi(2) + (p[1] - 0.5).powi(2) + (p[2] - 0.5).powi(2) < r * r).collect()
}

#[test]
fn a_single_inside_site_is_the_whole_box() {
    let c = check(&[[0.3, 0.6, 0.5]], &[true], "single");
    let v = TopologyReport::of(&c.mesh).signed_volume;
    assert!((v - 1.0).abs() < 1e-12, "{v}");
    assert_eq!(c.stats.num_mirrors, 6);
}

#[test]
fn all_inside_is_the_box_and_all_outside_is_empty() {
    let mut rng = Rng(7);
    let s = uniform(&mut rng, 500);
    let c = check(&s, &vec![true; 500], "all inside");
    assert!((TopologyReport::of(&c.mesh).signed_volume - 1.0).abs() < 1e-12);
    let c = check(&s, &vec![false; 500], "all outside");
    assert!(c.mesh.triangles.is_empty() && c.mesh.positions.is_empty());
}

#[test]
fn ball_labelled_sites_need_no_mirrors_and_approximate_the_ball() {
    let mut rng = Rng(11);
    let s = uniform(&mut rng, 20_000);
    let c = check(&s, &ball(&s, 0.35), "ball 20k");
    assert_eq!((c.stats.num_mirrors, c.stats.num_delaunay_passes), (0, 1));
    let v = TopologyReport::of(&c.mesh).signed_volume;
    let exact = 4.0 / 3.0 * std::f64::consts::PI * 0.35f64.powi(3);
    assert!((v - exact).abs() / exact < 0.05, "{v} vs {exact}");
    assert_eq!(TopologyReport::of(&c.mesh).genus, Some(0));
}

#[test]
fn lattice_labellings_split_vertices_where_cells_touch() {
    let s = lattice(6);
    let idx = |i: usize| (i / 36, (i / 6) % 6, i % 6);
    let checker: Vec<bool> = (0..s.len())
        .map(|i| {
            let (a, b, c) = idx(i);
            (a + b + c) % 2 == 0
        })
        .collect();
    let c = check(&s, &checker, "lattice checkerboard");
    assert!(c.stats.num_split_vertices > 0, "checkerboard cubes touch along edges");
    // Cubes of side 1/6: the crust encloses exactly half of the box.
    let v = TopologyReport::of(&c.mesh).signed_volume;
    assert!((v - 0.5).abs() < 1e-12, "{v}");
    check(&s, &ball(&s, 0.3), "lattice ball");
    let mut rng = Rng(3);
    let random: Vec<bool> = (0..s.len()).map(|_| rng.f() < 0.5).collect();
    check(&s, &random, "lattice random");
}

#[test]
fn clustered_and_duplicate_sites() {
    let mut rng = Rng(5);
    let mut s = Vec::new();
    for _ in 0..30 {
        let c = [0.2 + 0.6 * rng.f(), 0.2 + 0.6 * rng.f(), 0.2 + 0.6 * rng.f()];
        for _ in 0..8 {
            s.push([c[0] + 1e-9 * rng.f(), c[1] + 1e-9 * rng.f(), c[2] + 1e-9 * rng.f()]);
        }
    }
    s.push(s[0]); // an exact duplicate
    let labels: Vec<bool> = (0..s.len()).map(|i| (i / 8) % 2 == 0).collect();
    check(&s, &labels, "clusters within 1e-9");
}

#[test]
fn fewer_than_four_sites() {
    check(&[[0.5, 0.5, 0.5], [0.25, 0.5, 0.5]], &[true, false], "two sites");
    let c = check(&[[0.2, 0.5, 0.5], [0.5, 0.5, 0.5], [0.8, 0.5, 0.5]], &[true, true, false], "three collinear");
    let v = TopologyReport::of(&c.mesh).signed_volume;
    assert!((v - 0.65).abs() < 1e-12, "{v}");
}

#[test]
fn bad_inputs_are_errors() {
    let cfg = CrustConfig::default();
    assert!(Crust::extract(&[[0.5; 3]], &[true, false], &cfg).is_err());
    assert!(Crust::extract(&[[f64::NAN, 0.5, 0.5]], &[true], &cfg).is_err());
    assert!(Crust::extract(&[[1.0, 0.5, 0.5]], &[true], &cfg).is_err(), "on the box face");
    assert!(Crust::extract(&[[1.5, 0.5, 0.5]], &[true], &cfg).is_err());
}

#[derive(Debug, Clone, Copy)]
enum Labels {
    Random,
    Ball,
    HalfSpace,
    Sparse,
}

proptest! {
    // 2,000 generated cases: uniform sites (1 to 400) with random, ball, half-space and
    // sparse labellings; lattices with random labels.
    #![proptest_config(ProptestConfig { cases: 2000, failure_persistence: None, rng_seed: proptest::test_runner::RngSeed::Fixed(0xc0ffee), ..ProptestConfig::default() })]

    #[test]
    fn generated_cases_meet_every_guarantee(
        seed in any::<u64>(),
        k in 1usize..400,
        lattice_n in prop::option::weighted(0.15, 2usize..6),
        mode in prop::sample::select(vec![Labels::Random, Labels::Ball, Labels::HalfSpace, Labels::Sparse]),
    ) {
        let mut rng = Rng(seed | 1);
        let s = match lattice_n { Some(n) => lattice(n), None => uniform(&mut rng, k) };
        let labels: Vec<bool> = match mode {
            Labels::Random => s.iter().map(|_| rng.f() < 0.5).collect(),
            Labels::Ball => ball(&s, 0.2 + 0.25 * rng.f()),
            Labels::HalfSpace => s.iter().map(|p| p[0] + 0.3 * p[1] < 0.6).collect(),
            Labels::Sparse => s.iter().map(|_| rng.f() < 0.1).collect(),
        };
        check(&s, &labels, &format!("seed {seed} k {} {mode:?} lattice {lattice_n:?}", s.len()));
    }
}

#[test]
fn large_uniform_sets_with_random_labels() {
    for (k, seed) in [(1_000, 21), (10_000, 22), (100_000, 23)] {
        let mut rng = Rng(seed);
        let s = uniform(&mut rng, k);
        let labels: Vec<bool> = (0..k).map(|_| rng.f() < 0.5).collect();
        let t = std::time::Instant::now();
        let c = check(&s, &labels, &format!("uniform {k} random labels"));
        eprintln!("k = {k}: {} triangles, {:?}, checked in {:?}", c.mesh.triangles.len(), c.stats, t.elapsed());
    }
}
