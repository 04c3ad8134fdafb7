//! Cells of the branch and bound: sub-triangles of a source triangle with their corner
//! distances, the upper bound of the distance over a cell, and the 4-to-1 split.

use occupancy::distance::closest_point_triangle::closest_point_triangle;
use occupancy::Workspace;
use vf_common::vec3::distance;

use super::bounds::{at, covering_radius, max_of_min_affine};
use super::mesh::DistanceMesh;
use super::V3;

/// Corners, barycentric corners, distances and closest triangles of a child cell.
type ChildSpec = ([V3; 3], [[f64; 2]; 3], [f64; 3], [u32; 3]);

/// Barycentric corners of a whole triangle.
pub(super) const UNIT_BARY: [[f64; 2]; 3] = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];

/// One sub-triangle of a source triangle.
#[derive(Clone, Copy, Debug)]
pub(super) struct Cell {
    /// Direction: 0 = A → B, 1 = B → A.
    pub(super) dir: u8,
    /// Source triangle.
    pub(super) tri: u32,
    /// Dyadic barycentric coordinates `(u, v)` of the corners: `x = a + u (b − a) + v (c − a)`.
    pub(super) bary: [[f64; 2]; 3],
    /// Distances of the corners to the target mesh.
    pub(super) d: [f64; 3],
    /// Closest target triangle of each corner.
    pub(super) t: [u32; 3],
    /// Upper bound of the distance over the cell.
    pub(super) ub: f64,
}

/// The two directions of a search: `src[dir]` is measured against `tgt[dir]` (direction 0
/// is A → B, 1 is B → A).
pub(super) struct Engine<'a> {
    pub(super) src: [&'a DistanceMesh<'a>; 2],
    pub(super) tgt: [&'a DistanceMesh<'a>; 2],
}

impl Engine<'_> {
    /// Upper bound of `d(·, target)` over the cell with the given corners: the smaller of
    /// the Lipschitz bound and the convexity bound (see `max_of_min_affine`) over the
    /// corners' closest target triangles.
    pub(super) fn upper_bound(&self, dir: u8, x: &[V3; 3], d: &[f64; 3], t: &[u32; 3]) -> f64 {
        let dmax = d[0].max(d[1]).max(d[2]);
        if t[0] == t[1] && t[1] == t[2] {
            // One closest triangle for all corners: d(·, B) ≤ d(·, t) ≤ max_j d_j.
            return dmax;
        }
        let lipschitz = dmax + covering_radius(x);
        let tgt = self.tgt[dir as usize];
        let mut rows = [[0.0f64; 3]; 3];
        let mut k = 0;
        for i in 0..3 {
            if (i == 1 && t[1] == t[0]) || (i == 2 && (t[2] == t[0] || t[2] == t[1])) {
                continue;
            }
            let tri = tgt.corners(t[i]);
            for j in 0..3 {
                rows[k][j] = if t[j] == t[i] {
                    d[j]
                } else {
                    distance(x[j], closest_point_triangle(x[j], tri[0], tri[1], tri[2]))
                };
            }
            k += 1;
        }
        lipschitz.min(max_of_min_affine(&rows[..k]) * (1.0 + 1e-12))
    }

    /// Splits a cell 4-to-1 at its edge midpoints; returns the children and the largest
    /// midpoint distance with its point.
    pub(super) fn split(&self, c: &Cell, ws: &mut Workspace) -> ([Cell; 4], f64, V3) {
        let src_tri = self.src[c.dir as usize].corners(c.tri);
        let tgt = self.tgt[c.dir as usize];
        let b = c.bary;
        let mid = |i: usize, j: usize| [0.5 * (b[i][0] + b[j][0]), 0.5 * (b[i][1] + b[j][1])];
        let mb = [mid(0, 1), mid(1, 2), mid(2, 0)];
        let mut md = [0.0; 3];
        let mut mt = [0u32; 3];
        let mut mx = [[0.0; 3]; 3];
        let mut best = (f64::NEG_INFINITY, [0.0; 3]);
        for k in 0..3 {
            mx[k] = at(&src_tri, mb[k]);
            let cp = tgt.bvh.closest_point(mx[k], ws);
            md[k] = cp.squared_distance.sqrt();
            mt[k] = cp.triangle;
            if md[k] > best.0 {
                best = (md[k], mx[k]);
            }
        }
        let cx = b.map(|uv| at(&src_tri, uv));
        // Children: three corner cells and the middle one.
        let spec: [ChildSpec; 4] = [
            ([cx[0], mx[0], mx[2]], [b[0], mb[0], mb[2]], [c.d[0], md[0], md[2]], [c.t[0], mt[0], mt[2]]),
            ([mx[0], cx[1], mx[1]], [mb[0], b[1], mb[1]], [md[0], c.d[1], md[1]], [mt[0], c.t[1], mt[1]]),
            ([mx[2], mx[1], cx[2]], [mb[2], mb[1], b[2]], [md[2], md[1], c.d[2]], [mt[2], mt[1], c.t[2]]),
            ([mx[0], mx[1], mx[2]], mb, md, mt),
        ];
        let children = spec.map(|(x, bary, d, t)| Cell {
            dir: c.dir,
            tri: c.tri,
            bary,
            d,
            t,
            ub: self.upper_bound(c.dir, &x, &d, &t),
        });
        (children, best.0, best.1)
    }
}
