//! Property tests on small, mostly degenerate inputs: random points on tiny integer
//! grids (many coplanar, cospherical and duplicate points), checked by validate(), an
//! independent brute-force empty-sphere test, and order independence (the perturbation
//! makes the triangulation unique, so any permutation must give the same tetrahedra).

mod common;
use common::*;
use delaunay3::{Delaunay3, DelaunayError};
use proptest::prelude::*;

fn check(points: &[[f64; 3]], perm_seed: u64) -> Result<(), TestCaseError> {
    match Delaunay3::new(points) {
        Err(DelaunayError::Degenerate { .. }) => return Ok(()),
        Err(e) => return Err(TestCaseError::fail(format!("unexpected error {e}"))),
        Ok(dt) => {
            if let Err(e) = dt.validate() {
                return Err(TestCaseError::fail(format!("{e} for {points:?}")));
            }
            brute_force_delaunay(&dt);
            // Order independence.
            let mut shuffled = points.to_vec();
            let mut r = Rng(perm_seed);
            for i in (1..shuffled.len()).rev() {
                let j = r.below(i as u64 + 1) as usize;
                shuffled.swap(i, j);
            }
            let dt2 = Delaunay3::new(&shuffled).expect("shuffled");
            dt2.validate().map_err(|e| TestCaseError::fail(e.to_string()))?;
            prop_assert_eq!(tet_set_by_coords(&dt), tet_set_by_coords(&dt2));
        }
    }
    Ok(())
}

fn grid_points(side: i32, max_len: usize) -> impl Strategy<Value = Vec<[f64; 3]>> {
    prop::collection::vec((0..side, 0..side, 0..side).prop_map(|(x, y, z)| [x as f64, y as f64, z as f64]), 4..max_len)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    #[test]
    fn tiny_grid(points in grid_points(3, 30), seed in any::<u64>()) {
        check(&points, seed)?;
    }

    #[test]
    fn small_grid(points in grid_points(5, 80), seed in any::<u64>()) {
        check(&points, seed)?;
    }

    #[test]
    fn grid_points_on_two_planes(
        pts in prop::collection::vec((0..6i32, 0..6i32, prop::bool::ANY), 4..60),
        seed in any::<u64>(),
    ) {
        // z ∈ {0, 3}: two parallel planes, many cocircular and cospherical subsets.
        let points: Vec<[f64; 3]> = pts
            .iter()
            .map(|&(x, y, up)| [x as f64, y as f64, if up { 3.0 } else { 0.0 }])
            .collect();
        check(&points, seed)?;
    }

    #[test]
    fn cospherical_subsets(picks in prop::collection::vec(0usize..1000, 4..60), seed in any::<u64>()) {
        // Integer points on the sphere x²+y²+z² = 2,002 (all cospherical).
        let sols = sphere_integer_solutions(2_002);
        let points: Vec<[f64; 3]> = picks
            .iter()
            .map(|&i| sols[i % sols.len()].map(|c| c as f64))
            .collect();
        check(&points, seed)?;
    }

    #[test]
    fn random_floats(points in prop::collection::vec(prop::array::uniform3(-1.0f64..1.0), 4..60), seed in any::<u64>()) {
        check(&points, seed)?;
    }
}
