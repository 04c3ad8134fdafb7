//! Marching cubes with the asymptotic decider on cell faces and an exact interior test
//! (Lorensen & Cline 1987; Nielson & Hamann 1991; the interior ambiguity of Chernyaev 1995
//! and Lewiner et al. 2003), written from the papers: the surface in each cell has the
//! topology of the trilinear interpolant.
//!
//! # Convention (the same as `skimage.measure.marching_cubes`)
//!
//! A grid value is *above* when `value − level > 0` (a value equal to the level counts as
//! below). Every grid edge whose ends differ gets one vertex, placed by skimage's weighting
//! `t = w_hi / (w_lo + w_hi)` with `w = 1 / (ε + |value − level|)` and ε = 2.22e-16 (the
//! double machine epsilon): linear interpolation for all practical purposes, and defined
//! when an end lies exactly on the level. Vertex coordinates are `origin + spacing · (i, j,
//! k)` in grid index order (axis 0 first), like skimage's `verts` with `spacing`.
//!
//! # Topology
//!
//! In each cell the surface is built face by face: on every cube face the segments joining
//! the edge crossings keep the above region on their left (seen from outside the cube);
//! on a face with two diagonal above corners and two diagonal below corners the bilinear
//! interpolant's saddle decides (above corners joined iff `A·C − B·D > 0`, with values
//! relative to the level). A face's decision depends only on its four values, so the two
//! cells sharing it agree: the result is crack-free. Chaining the segments gives closed
//! polygons on the cube's surface. When there are two polygons around two regions of one
//! sign that the trilinear interpolant joins through the cell's inside (the "tunnel"
//! subcases of cases 4, 6, 7, 10, 12, 13), they are joined by a tube. The interior test is
//! exact: a sweep of the cell by planes along axis 2 whose bilinear slices change topology
//! only at ≤ 6 heights (see `ambiguity::connected_in_cube`).
//! [`Ambiguity::SeparateAbove`] and [`Ambiguity::JoinAbove`] are fixed face rules without
//! interior test (the classic 256-case table is `SeparateAbove`).
//!
//! # Triangulation
//!
//! Where a cell's polygons are those of the classic 256-case table (every face separating
//! its above corners and no tube: always with `SeparateAbove`, and in every unambiguous cell
//! and most ambiguous ones with the default), the cell's triangles are the table's (see
//! `classic::classic_triangles`; the polygons of all 256 cases are checked against the
//! table in that module's tests). Elsewhere each polygon is a fan from a corner whose diagonals all leave
//! the cell's faces, else around a new vertex at its centroid, and a tube is a ring of new
//! vertices with two strips.
//!
//! Against skimage (`tests/reference/test_baselines.py`): `SeparateAbove` gives exactly
//! `method="lorensen"`'s triangles, on noise too. The default gives exactly
//! `method="lewiner"`'s triangles on smooth fields and in every unambiguous cell; in
//! ambiguous cells Lewiner's tables triangulate their own way, and in about 1% of noise
//! cells their topology differs, where a sampled trilinear interpolant agrees with this
//! crate.
//!
//! # Output
//!
//! A welded [`TriMesh`]: one vertex per crossed grid edge (shared by the up to four cells
//! around it), triangles counter-clockwise seen from the side that is *not* solid (see
//! [`Inside`]). When the level set does not reach the grid's border the mesh is closed,
//! consistently oriented and edge-manifold. Where the solid region reaches the border the
//! surface simply stops there: the mesh is open along the border (pad the grid with a
//! value outside the solid to close it). A grid value exactly equal to the level puts the
//! vertices of all its crossed edges at that grid point (one shared vertex; skimage places
//! them within 1e-16 of it), and triangles that become degenerate by this are dropped:
//! every directed edge stays paired (closed), but the mesh can be non-manifold at such
//! points.
//!
//! # Layout
//!
//! `driver` runs the cells ([`marching_cubes()`]); `cube` numbers the cube's corners, edges
//! and faces; `ambiguity` holds the face rule and the exact interior test; `classic` the
//! classic table's triangulation; `polygons` the fans and tubes.

mod ambiguity;
mod classic;
mod cube;
mod driver;
mod polygons;

use mesh_io::TriMesh;

pub use driver::marching_cubes;

use crate::error::Result;
use crate::mlp::{DecoderKind, Mlp};
use crate::scalar::Real;

/// Which side of the level is the solid (the triangles face away from it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Inside {
    /// Values above the level are inside (occupancy, OccNet logits): triangle normals
    /// (right-hand rule) point towards decreasing values. skimage's
    /// `gradient_direction="ascent"`.
    Above,
    /// Values below the level are inside (signed distances): normals point towards
    /// increasing values. skimage's default `gradient_direction="descent"` gives this
    /// orientation (whatever its documentation suggests about "object greater than exterior").
    Below,
}

/// How a face with diagonal above corners and diagonal below corners is split.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ambiguity {
    /// The bilinear interpolant's saddle decides on faces, and an exact interior test
    /// joins polygons by tubes: the trilinear interpolant's topology in every cell.
    AsymptoticDecider,
    /// Above corners always separated: the classic 256-case table's choice, and exactly
    /// what `skimage.measure.marching_cubes(method="lorensen")` produces.
    SeparateAbove,
    /// Above corners always joined.
    JoinAbove,
}

/// Marching-cubes settings.
#[derive(Clone, Debug, PartialEq)]
pub struct McOptions {
    /// The iso-level of the surface.
    pub level: f64,
    /// Position of grid point `[0, 0, 0]`.
    pub origin: [f64; 3],
    /// Distance between grid points along each axis (> 0).
    pub spacing: [f64; 3],
    /// Which side of the level is the solid.
    pub inside: Inside,
    /// How ambiguous faces and cells are resolved.
    pub ambiguity: Ambiguity,
}

impl Default for McOptions {
    fn default() -> Self {
        McOptions {
            level: 0.0,
            origin: [0.0; 3],
            spacing: [1.0; 3],
            inside: Inside::Above,
            ambiguity: Ambiguity::AsymptoticDecider,
        }
    }
}

/// The grid resolution the study uses unless told otherwise (points per axis).
pub const DEFAULT_GRID_RES: usize = 128;

/// The zero level set of a decoder on the `res³` grid of the unit cube (values from
/// [`Mlp::eval_grid`]), oriented outward: OccNet logits are inside above 0, DeepSDF
/// distances below 0. Open where the surface reaches the cube's border.
pub fn extract_mesh<T: Real>(decoder: &Mlp<T>, res: usize) -> Result<TriMesh> {
    let grid = decoder.eval_grid(res)?;
    let h = 1.0 / (res - 1) as f64;
    let inside = match decoder.config().kind {
        DecoderKind::OccNet => Inside::Above,
        DecoderKind::DeepSdf => Inside::Below,
    };
    marching_cubes(grid.view(), &McOptions { spacing: [h; 3], inside, ..Default::default() })
}
