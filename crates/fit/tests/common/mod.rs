//! Settings shared by the fit crate's integration tests.

use fit::FitConfig;
use mesh_io::shapes::icosphere;
use mesh_io::TriMesh;

/// Polish steps in a test fit. The default's 400 (600 above K = 4,096) are most of a small
/// fit's time, twice over on a closed input (both polishes are tried); 100 steps pull the
/// faces onto the surface all the same at these sizes. The polish's own tests
/// (`polish.rs`) set theirs.
pub const POLISH_STEPS: usize = 100;

/// A fit small enough for a test: `k` sites, `steps` training steps on batches of 4,096,
/// `samples` training samples, `eval` evaluation samples and a [`POLISH_STEPS`]-step polish.
pub fn small(name: &str, k: usize, steps: usize, samples: usize, eval: usize) -> FitConfig {
    let mut c = FitConfig::new(name, k);
    c.train.steps = steps;
    c.train.batch = 4096;
    c.sampling.samples = samples;
    c.eval.samples = eval;
    if let Some(p) = c.polish.as_mut() {
        p.steps = POLISH_STEPS;
    }
    c
}

/// A unit sphere (icosphere of `subdivisions`) without its cap above z = 0.5: a bowl with a
/// hole of radius 0.87, the open mesh whose winding solid has a cap.
#[allow(dead_code)] // not every test file that includes this module fits a bowl
pub fn bowl(subdivisions: u32) -> TriMesh {
    let sphere = icosphere(subdivisions);
    let triangles = sphere
        .triangles
        .iter()
        .filter(|t| t.iter().map(|&v| sphere.positions[v as usize][2]).sum::<f64>() / 3.0 < 0.5)
        .copied()
        .collect();
    TriMesh { positions: sphere.positions, triangles }
}
