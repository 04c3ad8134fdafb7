//! Seeded, deterministic training samplers.
//!
//! Every sampler splits its output into chunks of [`SAMPLE_CHUNK`] points; chunk `c` draws
//! from its own generator derived from `(seed, sampler stream, c)`
//! ([`rng::ChunkRng::for_chunk`]). The chunk size is fixed, so the output depends only on
//! the arguments, never on the number of threads.

mod labelled;
pub mod rng;

pub use labelled::{labelled_samples, LabelledSamples, SampleSpec, LABEL_CHUNK};

use rayon::prelude::*;

use crate::OccupancyError;
use rng::{ChunkRng, Stream};
use vf_common::vec3::{add, cross, dot, scale, sub, V3};

/// Points per sampling chunk (fixed: part of the definition of the sample sequence).
pub const SAMPLE_CHUNK: usize = 4096;

/// `n` points uniform in the box `[lo, hi]`.
///
/// - `lo`, `hi`: box corners, f64, any frame (output in the same), `lo <= hi`.
/// - returns: #n×3 f64 points.
///
/// # Errors
/// [`OccupancyError::BadSampler`] if the box is not finite or inverted.
pub fn uniform_in_box(lo: V3, hi: V3, n: usize, seed: u64) -> Result<Vec<V3>, OccupancyError> {
    if !(0..3).all(|k| lo[k].is_finite() && hi[k].is_finite() && lo[k] <= hi[k]) {
        return Err(OccupancyError::BadSampler(format!("box {lo:?}..{hi:?} must be finite with min <= max")));
    }
    let ext = sub(hi, lo);
    let mut out = vec![[0.0; 3]; n];
    out.par_chunks_mut(SAMPLE_CHUNK).enumerate().for_each(|(c, chunk)| {
        let mut rng = ChunkRng::for_chunk(seed, Stream::SampleUniform, c as u64);
        for p in chunk {
            for k in 0..3 {
                p[k] = lo[k] + ext[k] * rng.uniform();
            }
        }
    });
    Ok(out)
}

/// Points on the surface with their normals.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SurfaceSamples {
    /// #n×3 f64 points on the mesh, mesh frame.
    pub points: Vec<V3>,
    /// #n×3 f64 unit normals of the sampled triangles (counter-clockwise orientation).
    pub normals: Vec<V3>,
    /// #n u32 index of the sampled triangle in the input mesh.
    pub triangles: Vec<u32>,
}

/// Area-weighted sampler of points on a triangle mesh.
#[derive(Clone, Debug)]
pub struct SurfaceSampler {
    /// #F×3 corners per triangle, f64, mesh frame.
    corners: Vec<[V3; 3]>,
    /// #F cumulative triangle areas, mesh units².
    cumulative_area: Vec<f64>,
}

impl SurfaceSampler {
    /// Prepares area-weighted sampling.
    ///
    /// - `positions`: #V×3 f64, mesh frame; `triangles`: #F×3 u32 zero-based.
    ///
    /// # Errors
    /// [`OccupancyError::VertexOutOfRange`], or [`OccupancyError::BadSampler`] when the
    /// total area is zero or not finite.
    pub fn new(positions: &[V3], triangles: &[[u32; 3]]) -> Result<Self, OccupancyError> {
        let mut corners = Vec::with_capacity(triangles.len());
        let mut cumulative_area = Vec::with_capacity(triangles.len());
        let mut total = 0.0;
        for (triangle, t) in triangles.iter().enumerate() {
            for &vertex in t {
                if vertex as usize >= positions.len() {
                    return Err(OccupancyError::VertexOutOfRange { triangle, vertex, num_vertices: positions.len() });
                }
            }
            let c = [positions[t[0] as usize], positions[t[1] as usize], positions[t[2] as usize]];
            let an = cross(sub(c[1], c[0]), sub(c[2], c[0]));
            total += 0.5 * dot(an, an).sqrt();
            corners.push(c);
            cumulative_area.push(total);
        }
        if !(total.is_finite() && total > 0.0) {
            return Err(OccupancyError::BadSampler(format!(
                "the mesh's total area is {total}; area-weighted sampling needs a positive, finite area"
            )));
        }
        Ok(SurfaceSampler { corners, cumulative_area })
    }

    /// Area-weighted sampler of a [`mesh_io::TriMesh`].
    ///
    /// # Errors
    /// As [`SurfaceSampler::new`].
    pub fn from_mesh(mesh: &mesh_io::TriMesh) -> Result<Self, OccupancyError> {
        Self::new(&mesh.positions, &mesh.triangles)
    }

    /// Total surface area, mesh units².
    pub fn total_area(&self) -> f64 {
        *self.cumulative_area.last().expect("non-empty")
    }

    /// One area-weighted sample: (point, unit normal, triangle index).
    fn draw(&self, rng: &mut ChunkRng) -> (V3, V3, u32) {
        let total = self.total_area();
        let x = rng.uniform() * total;
        // First triangle whose cumulative area exceeds x: it has positive area.
        let t = self.cumulative_area.partition_point(|&c| c <= x).min(self.corners.len() - 1);
        let [a, b, c] = self.corners[t];
        let s = rng.uniform().sqrt();
        let r2 = rng.uniform();
        let p = add(add(scale(a, 1.0 - s), scale(b, s * (1.0 - r2))), scale(c, s * r2));
        let an = cross(sub(b, a), sub(c, a));
        let n = scale(an, 1.0 / dot(an, an).sqrt());
        (p, n, t as u32)
    }

    /// `n` area-weighted surface samples (uniform over the surface).
    pub fn sample(&self, n: usize, seed: u64) -> SurfaceSamples {
        let mut rows = vec![([0.0; 3], [0.0; 3], 0u32); n];
        rows.par_chunks_mut(SAMPLE_CHUNK).enumerate().for_each(|(c, chunk)| {
            let mut rng = ChunkRng::for_chunk(seed, Stream::SampleSurface, c as u64);
            for r in chunk {
                *r = self.draw(&mut rng);
            }
        });
        SurfaceSamples {
            points: rows.iter().map(|r| r.0).collect(),
            normals: rows.iter().map(|r| r.1).collect(),
            triangles: rows.iter().map(|r| r.2).collect(),
        }
    }
}

/// `n` near-surface points: area-weighted surface samples plus isotropic Gaussian offsets
/// `N(0, σ² I)`.
///
/// - `sigmas`: standard deviations, mesh units, each finite and ≥ 0; the output is split
///   into `sigmas.len()` contiguous blocks of (nearly) equal size, point `i` using
///   `sigmas[i * sigmas.len() / n]`.
/// - returns: #n×3 f64 points, mesh frame.
///
/// # Errors
/// [`OccupancyError::BadSampler`] for an empty or invalid `sigmas`.
pub fn near_surface(sampler: &SurfaceSampler, n: usize, sigmas: &[f64], seed: u64) -> Result<Vec<V3>, OccupancyError> {
    if sigmas.is_empty() || sigmas.iter().any(|s| !(s.is_finite() && *s >= 0.0)) {
        return Err(OccupancyError::BadSampler(format!(
            "near-surface sigmas {sigmas:?} must be a non-empty list of finite values >= 0"
        )));
    }
    let k = sigmas.len();
    let mut out = vec![[0.0; 3]; n];
    out.par_chunks_mut(SAMPLE_CHUNK).enumerate().for_each(|(c, chunk)| {
        let mut rng = ChunkRng::for_chunk(seed, Stream::SampleNearSurface, c as u64);
        for (j, p) in chunk.iter_mut().enumerate() {
            let i = c * SAMPLE_CHUNK + j;
            let sigma = sigmas[((i as u128 * k as u128) / n as u128) as usize];
            let (q, _, _) = sampler.draw(&mut rng);
            *p = [q[0] + sigma * rng.normal(), q[1] + sigma * rng.normal(), q[2] + sigma * rng.normal()];
        }
    });
    Ok(out)
}
