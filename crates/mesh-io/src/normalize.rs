//! Normalisation into the unit cube and back.

use serde::{Deserialize, Serialize};

use crate::TriMesh;

/// A uniform scale and translation that maps a mesh's bounding box into the unit cube
/// `[0,1]³`, centred, with its longest side spanning `1 − 2·margin`.
///
/// `unit = (p − center) · scale + 0.5`, and the inverse `p = (unit − 0.5) / scale + center`.
/// Both directions are computed from the same two stored quantities, so a round trip
/// returns every coordinate to within a few ulps of the bounding box's extent (tested at
/// 1e-12 relative); [`UnitCubeTransform::to_unit_matrix`] and
/// [`UnitCubeTransform::from_unit_matrix`] give the same maps as 4×4 matrices, the latter
/// being what the sites file stores.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct UnitCubeTransform {
    /// Centre of the input bounding box, input units.
    pub center: [f64; 3],
    /// Unit-cube lengths per input length.
    pub scale: f64,
}

impl UnitCubeTransform {
    /// The transform for a bounding box, with `margin` (0 ≤ margin < 0.5) of empty space on
    /// each side of the longest axis. `None` when the box is a point or not finite.
    pub fn fit(bbox_min: [f64; 3], bbox_max: [f64; 3], margin: f64) -> Option<Self> {
        let extent = (0..3).map(|k| bbox_max[k] - bbox_min[k]).fold(0.0, f64::max);
        let scale = (1.0 - 2.0 * margin) / extent;
        let ok = extent > 0.0 && scale.is_finite() && scale > 0.0 && (0.0..0.5).contains(&margin);
        ok.then(|| UnitCubeTransform { center: [0, 1, 2].map(|k| 0.5 * bbox_min[k] + 0.5 * bbox_max[k]), scale })
    }

    /// The transform for a mesh's bounding box.
    pub fn of_mesh(mesh: &TriMesh, margin: f64) -> Option<Self> {
        let (lo, hi) = mesh.bounding_box();
        Self::fit(lo, hi, margin)
    }

    /// Input frame → unit cube.
    pub fn to_unit(&self, p: [f64; 3]) -> [f64; 3] {
        [0, 1, 2].map(|k| (p[k] - self.center[k]) * self.scale + 0.5)
    }

    /// Unit cube → input frame (the inverse of [`Self::to_unit`]).
    pub fn from_unit(&self, u: [f64; 3]) -> [f64; 3] {
        [0, 1, 2].map(|k| (u[k] - 0.5) / self.scale + self.center[k])
    }

    /// A copy of `mesh` mapped into the unit cube.
    pub fn mesh_to_unit(&self, mesh: &TriMesh) -> TriMesh {
        TriMesh {
            positions: mesh.positions.iter().map(|&p| self.to_unit(p)).collect(),
            triangles: mesh.triangles.clone(),
        }
    }

    /// A copy of `mesh` mapped from the unit cube back to the input frame; a negative
    /// scale (a mirroring map) reverses every triangle so outward stays outward.
    pub fn mesh_from_unit(&self, mesh: &TriMesh) -> TriMesh {
        let flip = self.scale < 0.0;
        TriMesh {
            positions: mesh.positions.iter().map(|&u| self.from_unit(u)).collect(),
            triangles: mesh.triangles.iter().map(|t| if flip { [t[0], t[2], t[1]] } else { *t }).collect(),
        }
    }

    /// 4×4 row-major matrix of [`Self::to_unit`] on homogeneous column vectors.
    pub fn to_unit_matrix(&self) -> [[f64; 4]; 4] {
        let s = self.scale;
        let c = self.center;
        [
            [s, 0.0, 0.0, 0.5 - c[0] * s],
            [0.0, s, 0.0, 0.5 - c[1] * s],
            [0.0, 0.0, s, 0.5 - c[2] * s],
            [0.0, 0.0, 0.0, 1.0],
        ]
    }

    /// 4×4 row-major matrix of [`Self::from_unit`] on homogeneous column vectors.
    pub fn from_unit_matrix(&self) -> [[f64; 4]; 4] {
        let s = 1.0 / self.scale;
        let c = self.center;
        [
            [s, 0.0, 0.0, c[0] - 0.5 * s],
            [0.0, s, 0.0, c[1] - 0.5 * s],
            [0.0, 0.0, s, c[2] - 0.5 * s],
            [0.0, 0.0, 0.0, 1.0],
        ]
    }
}
