//! The decoders' training data, analytically labelled, and the triangulated sphere the
//! main job fits.

use mesh_io::TriMesh;
use vf_common::rng::{ChunkRng, Stream};

use crate::SPHERE;

/// A uniformly random unit vector (rejection from the cube).
pub fn unit_dir(rng: &mut ChunkRng) -> [f64; 3] {
    loop {
        let d = [0, 1, 2].map(|_| 2.0 * rng.uniform() - 1.0);
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        if l > 1e-6 && l <= 1.0 {
            return d.map(|x| x / l);
        }
    }
}

/// `n` training points for the decoders: half uniform in the cube, half near the sphere
/// (σ = 0.01 and 0.003 alternately, the main job's near-surface spreads as fractions of
/// the diagonal of the sphere's box, rounded), labelled analytically (occupancy and signed
/// distance), in network coordinates [−1, 1]³ (centred inputs, as OccNet and DeepSDF use;
/// on raw [0, 1]³ inputs the small OccNets here stayed at the constant prediction). SDF
/// targets stay in unit-cube lengths.
pub fn sphere_data(n: usize, seed: u64) -> baselines::TrainingData {
    let mut rng = ChunkRng::for_chunk(seed, Stream::StudySphereData, 0);
    let sigmas = [0.01, 0.003];
    let mut points = Vec::with_capacity(n);
    for i in 0..n {
        if i < n / 2 {
            points.push([rng.uniform(), rng.uniform(), rng.uniform()]);
        } else {
            let d = unit_dir(&mut rng);
            let s = [0, 1, 2].map(|c| SPHERE.center[c] + SPHERE.radius * d[c]);
            let sigma = sigmas[i % 2];
            points.push([0, 1, 2].map(|c| (s[c] + sigma * rng.normal()).clamp(0.0, 1.0)));
        }
    }
    let sdf: Vec<f64> = points.iter().map(|p| SPHERE.distance(*p)).collect();
    let occ: Vec<f64> = sdf.iter().map(|&d| if d <= 0.0 { 1.0 } else { 0.0 }).collect();
    baselines::TrainingData {
        points: points.iter().map(|p| p.map(|x| 2.0 * x - 1.0)).collect(),
        occupancy: Some(occ),
        sdf: Some(sdf),
    }
}

/// The study's sphere as the main job's input: an icosphere with `subdivisions` levels
/// (every vertex on the sphere), in the unit cube. Its largest distance to the sphere is
/// the sagitta of its longest edge, returned with it.
pub fn sphere_mesh(subdivisions: u32) -> (TriMesh, f64) {
    let unit = mesh_io::shapes::icosphere(subdivisions);
    let positions: Vec<[f64; 3]> =
        unit.positions.iter().map(|p| [0, 1, 2].map(|c| SPHERE.center[c] + SPHERE.radius * p[c])).collect();
    let mut longest: f64 = 0.0;
    for t in &unit.triangles {
        for e in 0..3 {
            let (a, b) = (positions[t[e] as usize], positions[t[(e + 1) % 3] as usize]);
            longest = longest.max(((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt());
        }
    }
    // A triangle's farthest point from the sphere is inside its circumcircle, at most the
    // sagitta of a chord as long as the circumdiameter; for the icosphere's near-equilateral
    // triangles that is within 2/√3 of the longest edge.
    let chord = longest * 2.0 / 3f64.sqrt();
    let r = SPHERE.radius;
    let sagitta = r - (r * r - 0.25 * chord * chord).max(0.0).sqrt();
    (TriMesh { positions, triangles: unit.triangles }, sagitta)
}
