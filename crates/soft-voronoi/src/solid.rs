//! Target solids for the signed-distance regulariser and for labelling: a triangle mesh
//! (through the occupancy crate's oracle) and an analytic sphere.

use occupancy::{MeshOracle, WindingMode, Workspace};
use rayon::prelude::*;

use crate::losses::{Located, Solid};

/// Points per parallel chunk (fixed, so results never depend on the thread count).
const CHUNK: usize = 256;

/// A triangle mesh as a solid: inside by the workspace's one rule
/// ([`occupancy::Config::is_inside_winding`]: |generalized winding number| ≥ 0.5, fast mode
/// with the exact fallback on both sides of the threshold), closest point by BVH.
pub struct MeshSolid<'a> {
    /// The oracle, built on the mesh in the frame of the queries.
    pub oracle: &'a MeshOracle,
}

impl MeshSolid<'_> {
    /// Inside test for each point ([`MeshOracle::is_inside`]).
    pub fn inside(&self, points: &[[f64; 3]]) -> Vec<bool> {
        let mut out = vec![false; points.len()];
        out.par_chunks_mut(CHUNK).zip(points.par_chunks(CHUNK)).for_each(|(o, ps)| {
            let mut ws = Workspace::new();
            for (o, &p) in o.iter_mut().zip(ps) {
                *o = self.oracle.is_inside(p, WindingMode::Fast, &mut ws);
            }
        });
        out
    }
}

impl Solid for MeshSolid<'_> {
    fn locate(&self, points: &[[f64; 3]]) -> Vec<Located> {
        let mut out = vec![Located { inside: false, closest: [0.0; 3] }; points.len()];
        out.par_chunks_mut(CHUNK).zip(points.par_chunks(CHUNK)).for_each(|(o, ps)| {
            let mut ws = Workspace::new();
            for (o, &p) in o.iter_mut().zip(ps) {
                let inside = self.oracle.is_inside(p, WindingMode::Fast, &mut ws);
                let closest = self.oracle.closest_point(p, &mut ws).point;
                *o = Located { inside, closest };
            }
        });
        out
    }
}

/// A solid ball: the workspace's one sphere type ([`mesh_io::shapes::Sphere`]), also the
/// reference of the certified sphere Hausdorff in `metrics`.
pub use mesh_io::shapes::Sphere;

impl Solid for Sphere {
    fn locate(&self, points: &[[f64; 3]]) -> Vec<Located> {
        points
            .iter()
            .map(|&p| {
                let d = self.center_distance(p);
                let dir = if d > 0.0 { [0, 1, 2].map(|c| (p[c] - self.center[c]) / d) } else { [1.0, 0.0, 0.0] };
                Located { inside: d <= self.radius, closest: [0, 1, 2].map(|c| self.center[c] + self.radius * dir[c]) }
            })
            .collect()
    }
}
