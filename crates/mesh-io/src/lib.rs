//! Triangle meshes for voronoi-fit.
//!
//! Entry type: [`TriMesh`]. Entry functions: [`read_mesh`] (any supported format, chosen by
//! content and extension; refuses coordinates outside the range of [`limits`]),
//! [`write_mesh`] / [`write_gltf`] (atomic), [`TopologyReport::of`] and
//! [`UnitCubeTransform`]. Checks before long work: [`OutputFormat::from_path`],
//! [`check_output_location`], [`check_f32_resolution`]. Crack repair:
//! [`weld::weld_tolerance`], [`weld::count_near_pairs`]. Open meshes: [`orient_consistently`],
//! [`fill_planar_holes`]. See the crate's README.md.

pub mod atomic;
mod dsu;
pub mod error;
pub mod holes;
pub mod limits;
pub mod normalize;
pub mod orient;
pub mod output;
pub mod read;
pub mod shapes;
pub mod topology;
pub mod weld;
pub mod write;

pub use atomic::atomic_write;
pub use error::{ErrorKind, Location, MeshError};
pub use holes::{fill_planar_holes, FillOptions, HoleFilling};
pub use limits::{check_f32_resolution, check_representable};
pub use normalize::UnitCubeTransform;
pub use orient::{orient_consistently, Reorientation};
pub use output::{check_output_location, OutputFormat};
pub use read::{read_mesh, read_mesh_from_bytes, Format};
pub use topology::TopologyReport;
pub use weld::{weld_tolerance, WeldStats};
pub use write::{
    vertex_normals, write_gltf, write_mesh, write_mesh_with, write_obj, write_ply, GltfLayout, Normals, SceneMesh,
    DEFAULT_CREASE_DEGREES,
};

/// An indexed triangle mesh in f64.
///
/// - `positions`: #V×3 f64, in the file's own units and frame.
/// - `triangles`: #F×3 u32, zero-based indices into `positions`, counter-clockwise seen
///   from outside when the mesh is consistently oriented.
///
/// Readers guarantee every coordinate is finite and within the representable range
/// ([`check_representable`]), every index is in range and the mesh has at least one
/// triangle; code that builds a `TriMesh` by hand can check the same with
/// [`TriMesh::validate`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions.
    pub positions: Vec<[f64; 3]>,
    /// Triangles as three vertex indices, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

impl TriMesh {
    /// Axis-aligned bounding box `(min, max)` of all positions; `([∞;3], [-∞;3])` when
    /// there are none.
    pub fn bounding_box(&self) -> ([f64; 3], [f64; 3]) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &self.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        (lo, hi)
    }

    /// Length of the bounding box diagonal (0 for an empty mesh).
    pub fn diagonal(&self) -> f64 {
        let (lo, hi) = self.bounding_box();
        if self.positions.is_empty() {
            return 0.0;
        }
        ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt()
    }

    /// The triangles as corner positions (bit patterns), each rotated to start at its
    /// smallest corner (orientation kept) and the list sorted: equal for two meshes with the
    /// same oriented triangles whatever their vertex numbering.
    pub fn canonical_triangles(&self) -> Vec<[[u64; 3]; 3]> {
        let mut v: Vec<[[u64; 3]; 3]> = self
            .triangles
            .iter()
            .map(|t| {
                let c = t.map(|i| self.positions[i as usize].map(f64::to_bits));
                let k = (0..3).min_by_key(|&k| c[k]).unwrap_or(0);
                [c[k], c[(k + 1) % 3], c[(k + 2) % 3]]
            })
            .collect();
        v.sort_unstable();
        v
    }

    /// Check what readers guarantee: finite coordinates in the representable range
    /// ([`check_representable`]), indices in range (the mesh may be empty). `what` names
    /// the mesh in the error.
    pub fn validate(&self, what: &std::path::Path) -> Result<(), MeshError> {
        read::check_contents(self, what)
    }
}
