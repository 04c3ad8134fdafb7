//! Building the triangle BVH with obvhs and deriving the f64 per-node arrays.

use std::time::Duration;

use glam::Vec3A;
use obvhs::{aabb::Aabb, bvh2::builder::build_bvh2, BvhBuildParams};

use super::{HotBox, TriangleBvh};
use crate::config::BvhPreset;
use vf_common::vec3::{cross, dot, sub, V3};

/// f32 value `<= x` (for the lower corner of an f32 box that must contain `x`).
fn f32_down(x: f64) -> f32 {
    let y = x.clamp(-(f32::MAX as f64), f32::MAX as f64) as f32;
    if (y as f64) > x {
        y.next_down()
    } else {
        y
    }
}

/// f32 value `>= x`.
fn f32_up(x: f64) -> f32 {
    let y = x.clamp(-(f32::MAX as f64), f32::MAX as f64) as f32;
    if (y as f64) < x {
        y.next_up()
    } else {
        y
    }
}

/// Builds the BVH over triangles given by their corners.
///
/// - `corners`: #F triangles, each three f64 corners in the mesh frame (input order).
/// - `preset`: obvhs build preset (never with spatial splits).
/// - `build_leaf_size`: most triangles per obvhs leaf (1..=255): the tree the winding
///   numbers walk.
/// - `box_leaf_size`: the box traversals (closest points, crossing counts) stop at the
///   first node with at most this many triangles (its slot range is contiguous) and test
///   them all, so they walk a tree with leaves of this size (≥ `build_leaf_size` to
///   have an effect).
///
/// # Complexity
/// O(F log F) for the obvhs build plus O(F) for the f64 arrays.
///
/// # Panics
/// If `corners` is empty (the oracle checks this first).
pub fn build_triangle_bvh(
    corners: &[[V3; 3]],
    preset: BvhPreset,
    build_leaf_size: u32,
    box_leaf_size: u32,
) -> TriangleBvh {
    assert!(!corners.is_empty(), "BVH needs at least one triangle");
    let aabbs: Vec<Aabb> = corners
        .iter()
        .map(|t| {
            let mut lo = [0f32; 3];
            let mut hi = [0f32; 3];
            for k in 0..3 {
                let mn = t[0][k].min(t[1][k]).min(t[2][k]);
                let mx = t[0][k].max(t[1][k]).max(t[2][k]);
                lo[k] = f32_down(mn);
                hi[k] = f32_up(mx);
            }
            Aabb::new(Vec3A::from(lo), Vec3A::from(hi))
        })
        .collect();
    let mut params = match preset {
        BvhPreset::VeryFast => BvhBuildParams::very_fast_build(),
        BvhPreset::Fast => BvhBuildParams::fast_build(),
        BvhPreset::Medium => BvhBuildParams::medium_build(),
    };
    // Spatial splits would put a triangle in two leaves and double its winding number.
    params.pre_split = false;
    params.max_prims_per_leaf = build_leaf_size.clamp(1, 255);
    let mut build_time = Duration::ZERO;
    let bvh = build_bvh2(&aabbs, params, &mut build_time);

    let num_nodes = bvh.nodes.len();
    let mut range = vec![[0u32; 2]; num_nodes];
    let mut box_lo = vec![[f64::INFINITY; 3]; num_nodes];
    let mut box_hi = vec![[f64::NEG_INFINITY; 3]; num_nodes];
    let mut slot_corners: Vec<[V3; 3]> = Vec::with_capacity(corners.len());
    let mut tri_ids: Vec<u32> = Vec::with_capacity(corners.len());

    // Iterative depth-first traversal; `false` = entering, `true` = leaving (post-order).
    let mut stack: Vec<(u32, bool)> = vec![(0, false)];
    while let Some((n, leaving)) = stack.pop() {
        let node = &bvh.nodes[n as usize];
        if node.prim_count > 0 {
            let lo = slot_corners.len() as u32;
            let first = node.first_index as usize;
            let mut blo = [f64::INFINITY; 3];
            let mut bhi = [f64::NEG_INFINITY; 3];
            for &prim in &bvh.primitive_indices[first..first + node.prim_count as usize] {
                let t = corners[prim as usize];
                for c in t {
                    for k in 0..3 {
                        blo[k] = blo[k].min(c[k]);
                        bhi[k] = bhi[k].max(c[k]);
                    }
                }
                slot_corners.push(t);
                tri_ids.push(prim);
            }
            range[n as usize] = [lo, slot_corners.len() as u32];
            box_lo[n as usize] = blo;
            box_hi[n as usize] = bhi;
        } else if !leaving {
            let l = node.first_index;
            stack.push((n, true));
            // Push right first so the left subtree takes the lower slots.
            stack.push((l + 1, false));
            stack.push((l, false));
        } else {
            let l = node.first_index as usize;
            range[n as usize] = [range[l][0], range[l + 1][1]];
            let mut blo = box_lo[l];
            let mut bhi = box_hi[l];
            for k in 0..3 {
                blo[k] = blo[k].min(box_lo[l + 1][k]);
                bhi[k] = bhi[k].max(box_hi[l + 1][k]);
            }
            box_lo[n as usize] = blo;
            box_hi[n as usize] = bhi;
        }
    }
    let hot_boxes = (0..num_nodes)
        .map(|n| HotBox {
            lo: box_lo[n],
            hi: box_hi[n],
            link: if bvh.nodes[n].prim_count > 0 || range[n][1] - range[n][0] <= box_leaf_size {
                range[n]
            } else {
                [bvh.nodes[n].first_index, u32::MAX]
            },
        })
        .collect();
    let planes = slot_corners
        .iter()
        .map(|t| {
            let nrm = cross(sub(t[1], t[0]), sub(t[2], t[0]));
            let len = dot(nrm, nrm).sqrt();
            if len > 0.0 && len.is_finite() {
                let u = [nrm[0] / len, nrm[1] / len, nrm[2] / len];
                [u[0], u[1], u[2], dot(u, t[0])]
            } else {
                [0.0; 4]
            }
        })
        .collect();
    TriangleBvh { bvh, range, box_lo, box_hi, corners: slot_corners, tri_ids, hot_boxes, planes }
}
