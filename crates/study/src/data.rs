//! The sphere's training data, analytically labelled.

use soft_voronoi::TrainingData;
use vf_common::rng::{ChunkRng, Stream};

use crate::SPHERE;

/// The sphere's training data, analytically labelled.
pub struct Data {
    /// For the Voronoi sites (unit cube).
    pub voronoi: TrainingData,
    /// For the decoders (network coordinates [−1, 1]³).
    pub mlp: baselines::TrainingData,
}

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

/// `n` training points: half uniform in the cube, half near the sphere (σ = 0.01 and
/// 0.003 alternately), labelled analytically; the near half's sphere points and normals
/// are the surface samples.
pub fn sphere_data(n: usize, seed: u64) -> Data {
    let mut rng = ChunkRng::for_chunk(seed, Stream::StudySphereData, 0);
    let sigmas = [0.01, 0.003];
    let mut points = Vec::with_capacity(n);
    let mut surface = Vec::with_capacity(n / 2);
    let mut normals = Vec::with_capacity(n / 2);
    for i in 0..n {
        if i < n / 2 {
            points.push([rng.uniform(), rng.uniform(), rng.uniform()]);
        } else {
            let d = unit_dir(&mut rng);
            let s = [0, 1, 2].map(|c| SPHERE.center[c] + SPHERE.radius * d[c]);
            let sigma = sigmas[i % 2];
            points.push([0, 1, 2].map(|c| (s[c] + sigma * rng.normal()).clamp(0.0, 1.0)));
            surface.push(s);
            normals.push(d);
        }
    }
    let dist = |p: &[f64; 3]| SPHERE.distance(*p);
    let inside: Vec<bool> = points.iter().map(|p| dist(p) <= 0.0).collect();
    let sdf: Vec<f64> = points.iter().map(dist).collect();
    let occ: Vec<f64> = inside.iter().map(|&b| if b { 1.0 } else { 0.0 }).collect();
    Data {
        voronoi: TrainingData { points: points.clone(), occupancy: inside, surface, normals },
        // The decoders see coordinates in [−1, 1]³ (centred inputs, as OccNet and DeepSDF
        // use; on raw [0, 1]³ inputs the small OccNets here stayed at the constant
        // prediction for the whole budget). SDF targets stay in unit-cube lengths.
        mlp: baselines::TrainingData {
            points: points.iter().map(|p| p.map(|x| 2.0 * x - 1.0)).collect(),
            occupancy: Some(occ),
            sdf: Some(sdf),
        },
    }
}
