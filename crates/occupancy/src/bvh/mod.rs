//! Triangle BVH: obvhs `Bvh2` topology plus this crate's per-node f64 data in parallel
//! arrays indexed by obvhs node id.
//!
//! obvhs builds in f32 from (outward-rounded) triangle boxes; this crate only uses its tree
//! *topology* (`Bvh2Node::prim_count`, `first_index` and `Bvh2::primitive_indices`) and
//! recomputes every bound it relies on in f64 from the triangles, so results do not depend
//! on f32 rounding. Spatial splits are never used: each triangle lies in exactly one leaf
//! (checked by [`TriangleBvh::validate`]), which winding-number sums require.

mod build;

pub use build::build_triangle_bvh;

use obvhs::bvh2::Bvh2;

use vf_common::vec3::V3;

/// A BVH over the triangles of a mesh.
///
/// Triangles are stored in *slot* order: the depth-first order of the leaves, so that every
/// subtree covers one contiguous slot range.
#[derive(Clone)]
pub struct TriangleBvh {
    /// obvhs topology. Node 0 is the root; an inner node's children are `first_index` and
    /// `first_index + 1`; a leaf has `prim_count > 0`.
    pub(crate) bvh: Bvh2,
    /// Per node (#nodes): slot range `[lo, hi)` of the triangles below it. Nodes not
    /// reachable from the root (obvhs may leave some after collapsing) have `[0, 0)`.
    pub(crate) range: Vec<[u32; 2]>,
    /// Per node (#nodes): tight f64 box min corner, mesh frame.
    pub(crate) box_lo: Vec<V3>,
    /// Per node (#nodes): tight f64 box max corner, mesh frame.
    pub(crate) box_hi: Vec<V3>,
    /// Per slot (#F): the triangle's corners, f64, mesh frame, in the input's order.
    pub(crate) corners: Vec<[V3; 3]>,
    /// Per slot (#F): index of the triangle in the input mesh.
    pub(crate) tri_ids: Vec<u32>,
    /// Per node (#nodes): `[lo, hi, lo, hi, lo, hi]` of the f64 box interleaved per axis
    /// followed by the link (inner: `[left child, u32::MAX]`, leaf: slot range) — the
    /// closest-point traversal's only per-node read.
    pub(crate) hot_boxes: Vec<HotBox>,
    /// Per slot (#F): supporting plane `[nx, ny, nz, n·a]` with unit normal (zero for a
    /// degenerate triangle), mesh frame; `|n·q − n·a|` is a lower bound of the distance.
    pub(crate) planes: Vec<[f64; 4]>,
}

/// Box and link of one node, for the closest-point traversal.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct HotBox {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    pub link: [u32; 2],
}

impl TriangleBvh {
    /// Number of nodes in the obvhs node array (including any unreachable ones).
    pub fn num_nodes(&self) -> usize {
        self.bvh.nodes.len()
    }

    /// Number of triangles.
    pub fn num_triangles(&self) -> usize {
        self.corners.len()
    }

    /// Whether node `n` is a leaf.
    #[inline(always)]
    pub(crate) fn is_leaf(&self, n: u32) -> bool {
        self.bvh.nodes[n as usize].prim_count > 0
    }

    /// Left child of inner node `n` (the right one is `left + 1`).
    #[inline(always)]
    pub(crate) fn left_child(&self, n: u32) -> u32 {
        self.bvh.nodes[n as usize].first_index
    }

    /// Checks the invariants completely: every triangle in exactly one leaf, slot ranges
    /// nested and contiguous, f64 boxes contain their triangles and children.
    ///
    /// # Panics
    /// Never; returns a description of the first violation instead.
    pub fn validate(&self) -> Result<(), String> {
        let num_tris = self.corners.len();
        if self.tri_ids.len() != num_tris {
            return Err("tri_ids and corners differ in length".into());
        }
        let mut seen = vec![false; num_tris];
        for &t in &self.tri_ids {
            let t = t as usize;
            if t >= num_tris || seen[t] {
                return Err(format!("triangle {t} appears twice or is out of range"));
            }
            seen[t] = true;
        }
        if self.range[0] != [0, num_tris as u32] {
            return Err(format!("root covers {:?}, not all {num_tris} slots", self.range[0]));
        }
        let mut stack = vec![0u32];
        let mut covered = 0usize;
        while let Some(n) = stack.pop() {
            let [lo, hi] = self.range[n as usize];
            if lo >= hi {
                return Err(format!("reachable node {n} has empty range"));
            }
            let (blo, bhi) = (self.box_lo[n as usize], self.box_hi[n as usize]);
            for s in lo..hi {
                for c in self.corners[s as usize] {
                    for k in 0..3 {
                        if c[k] < blo[k] || c[k] > bhi[k] {
                            return Err(format!("node {n} box misses a corner of slot {s}"));
                        }
                    }
                }
            }
            if self.is_leaf(n) {
                let count = self.bvh.nodes[n as usize].prim_count;
                if hi - lo != count {
                    return Err(format!("leaf {n} range {lo}..{hi} but prim_count {count}"));
                }
                covered += (hi - lo) as usize;
            } else {
                let l = self.left_child(n);
                let (rl, rr) = (self.range[l as usize], self.range[l as usize + 1]);
                if rl[0] != lo || rl[1] != rr[0] || rr[1] != hi {
                    return Err(format!("children of {n} do not tile its range"));
                }
                stack.push(l);
                stack.push(l + 1);
            }
        }
        if covered != num_tris {
            return Err(format!("leaves cover {covered} slots, expected {num_tris}"));
        }
        Ok(())
    }
}
