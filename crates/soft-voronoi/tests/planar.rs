//! The kernel and losses in two dimensions (the MNIST autoencoder's): the same generic code
//! as in 3D, checked against finite differences of the sparse kernel itself.

use soft_voronoi::kernel::{self, Kernel, Scratch, SiteIndex};
use soft_voronoi::losses::{self, Located, SiteGraph};
use vf_common::{ChunkRng, Stream};

/// Sites, their labels, points and their occupancy.
type Setup = (Vec<[f64; 2]>, Vec<bool>, Vec<[f64; 2]>, Vec<bool>);

fn setup(k: usize, n: usize, seed: u64) -> Setup {
    let mut rng = ChunkRng::for_chunk(seed, Stream::Test, 2000);
    let sites: Vec<[f64; 2]> = (0..k).map(|_| [rng.uniform(), rng.uniform()]).collect();
    let labels: Vec<bool> = (0..k).map(|i| i % 2 == 0).collect();
    // Points near bisectors of site pairs, so the softmax is not saturated.
    let mut points = Vec::new();
    for i in 0..n {
        let (a, b) = (sites[i % k], sites[(i * 7 + 3) % k]);
        let t = 0.5 + 0.05 * (rng.uniform() - 0.5);
        points.push([a[0] + t * (b[0] - a[0]) + 0.01 * rng.normal(), a[1] + t * (b[1] - a[1]) + 0.01 * rng.normal()]);
    }
    let occ: Vec<bool> = points.iter().map(|p| (p[0] - 0.5).hypot(p[1] - 0.5) < 0.3).collect();
    (sites, labels, points, occ)
}

fn total(
    kern: &Kernel,
    sites: &[[f64; 2]],
    labels: &[bool],
    pts: &[[f64; 2]],
    occ: &[bool],
    loc: &[Located<2>],
    graph: &SiteGraph,
) -> (f64, Vec<[f64; 2]>) {
    let index = SiteIndex::<2>::new(sites);
    let mut g = vec![[0.0; 2]; sites.len()];
    let mut l = losses::reconstruction(kern, &index, sites, labels, pts, occ, 1.0, &mut g);
    l += 0.7 * losses::bounds(sites, 0.7, &mut g);
    l += 0.3 * losses::signed_distance_cached(loc, sites, labels, 0.3, &mut g);
    l += 0.5 * losses::centroidal(graph, sites, 0.5, &mut g);
    (l, g)
}

#[test]
fn two_dimensional_losses_match_finite_differences() {
    for (seed, beta) in [(1u64, 20.0), (2, 200.0), (3, 2000.0)] {
        let (mut sites, labels, pts, occ) = setup(24, 300, seed);
        // Two sites outside the square, so the bounds term is active.
        sites[3] = [-0.05, 0.4];
        sites[8] = [0.5, 1.07];
        let kern = Kernel::new(beta);
        // Closest points on the circle of the occupancy, sides as the occupancy says.
        let loc: Vec<Located<2>> = sites
            .iter()
            .map(|p| {
                let (dx, dy) = (p[0] - 0.5, p[1] - 0.5);
                let r = dx.hypot(dy).max(1e-12);
                Located { inside: r < 0.3, closest: [0.5 + 0.3 * dx / r, 0.5 + 0.3 * dy / r] }
            })
            .collect();
        let graph =
            SiteGraph::from_edges(sites.len(), (0..sites.len() as u32).map(|i| (i, (i + 1) % sites.len() as u32)));
        let (_, g) = total(&kern, &sites, &labels, &pts, &occ, &loc, &graph);
        let h = 1e-3 / beta;
        let mut checked = 0;
        for j in 0..sites.len() {
            for c in 0..2 {
                let mut p = sites.clone();
                p[j][c] += h;
                let up = total(&kern, &p, &labels, &pts, &occ, &loc, &graph).0;
                p[j][c] -= 2.0 * h;
                let down = total(&kern, &p, &labels, &pts, &occ, &loc, &graph).0;
                let fd = (up - down) / (2.0 * h);
                let tol = 1e-4 * (1.0 + fd.abs()) + 1e-6 * beta;
                assert!(
                    (fd - g[j][c]).abs() <= tol,
                    "beta {beta} site {j} coord {c}: finite difference {fd} vs {}",
                    g[j][c]
                );
                checked += usize::from(g[j][c].abs() > 1e-3);
            }
        }
        assert!(checked > 10, "beta {beta}: only {checked} non-trivial gradient entries");
    }
}

#[test]
fn two_dimensional_kernel_is_the_nearest_site_label_at_high_beta() {
    let (sites, labels, pts, _) = setup(50, 400, 7);
    let kern = Kernel::new(1e7);
    let index = SiteIndex::<2>::new(&sites);
    let mut s = Scratch::default();
    for x in pts {
        let nearest = (0..sites.len())
            .min_by(|&a, &b| kernel::distance(x, sites[a]).total_cmp(&kernel::distance(x, sites[b])))
            .unwrap();
        let v = kernel::value(&kern, &index, &sites, &labels, x, &mut s);
        let hard = kernel::hard_label(&index, &sites, &labels, x);
        assert_eq!(hard, labels[nearest]);
        // Away from a tie, the soft value is the hard label.
        let mut d: Vec<f64> = sites.iter().map(|&p| kernel::distance(x, p)).collect();
        d.sort_by(f64::total_cmp);
        if d[1] - d[0] > 1e-5 {
            assert!((v - f64::from(u8::from(hard))).abs() < 1e-9, "{v} vs {hard}");
        }
    }
}
