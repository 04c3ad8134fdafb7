//! Target solids for the signed-distance regulariser and for labelling: a triangle mesh
//! (through the occupancy crate's oracle) and an analytic sphere.

use occupancy::{MeshOracle, WindingMode, Workspace};
use rayon::prelude::*;

use crate::losses::{Located, Solid};

/// Points per parallel chunk (fixed, so results never depend on the thread count).
const CHUNK: usize = 256;

/// A triangle mesh as a solid: inside where |generalized winding number| ≥ 0.5 (fast
/// mode with exact fallback near the threshold), closest point by BVH.
///
/// The absolute value makes a closed body whose triangles all face inward count as solid,
/// like one facing outward; meshes with such bodies are common (mirrored exports).
pub struct MeshSolid<'a> {
    /// The oracle, built on the mesh in the frame of the queries.
    pub oracle: &'a MeshOracle,
}

impl MeshSolid<'_> {
    /// Inside test for each point (|w| ≥ 0.5).
    pub fn inside(&self, points: &[[f64; 3]]) -> Vec<bool> {
        let mut out = vec![false; points.len()];
        out.par_chunks_mut(CHUNK).zip(points.par_chunks(CHUNK)).for_each(|(o, ps)| {
            let mut ws = Workspace::new();
            for (o, &p) in o.iter_mut().zip(ps) {
                *o = inside_winding(self.oracle.winding_number(p, WindingMode::Fast, &mut ws));
            }
        });
        out
    }
}

/// The occupancy rule used for training and evaluation: |w| ≥ 0.5.
pub fn inside_winding(w: f64) -> bool {
    w.abs() >= 0.5
}

impl Solid for MeshSolid<'_> {
    fn locate(&self, points: &[[f64; 3]]) -> Vec<Located> {
        let mut out = vec![Located { inside: false, closest: [0.0; 3] }; points.len()];
        out.par_chunks_mut(CHUNK).zip(points.par_chunks(CHUNK)).for_each(|(o, ps)| {
            let mut ws = Workspace::new();
            for (o, &p) in o.iter_mut().zip(ps) {
                let inside = inside_winding(self.oracle.winding_number(p, WindingMode::Fast, &mut ws));
                let closest = self.oracle.closest_point(p, &mut ws).point;
                *o = Located { inside, closest };
            }
        });
        out
    }
}

/// A solid ball.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub center: [f64; 3],
    /// Radius (> 0).
    pub radius: f64,
}

impl Sphere {
    /// Whether `p` is inside the closed ball.
    pub fn contains(&self, p: [f64; 3]) -> bool {
        crate::kernel::distance(p, self.center) <= self.radius
    }
}

impl Solid for Sphere {
    fn locate(&self, points: &[[f64; 3]]) -> Vec<Located> {
        points
            .iter()
            .map(|&p| {
                let d = crate::kernel::distance(p, self.center);
                let dir = if d > 0.0 { [0, 1, 2].map(|c| (p[c] - self.center[c]) / d) } else { [1.0, 0.0, 0.0] };
                Located { inside: d <= self.radius, closest: [0, 1, 2].map(|c| self.center[c] + self.radius * dir[c]) }
            })
            .collect()
    }
}
