//! Exact closest points and distances to the mesh.

pub mod closest_point_triangle;

use crate::bvh::TriangleBvh;
use crate::vec3::{box_distance_squared, norm_squared, sub, V3};
use closest_point_triangle::closest_point_triangle;

/// The closest point of the mesh to a query.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct ClosestPoint {
    /// Closest point on the mesh, f64, mesh frame.
    pub point: V3,
    /// Squared Euclidean distance from the query to `point`, mesh units².
    pub squared_distance: f64,
    /// Index (into the input mesh's triangles) of a triangle containing `point`.
    pub triangle: u32,
}

/// Branch-and-bound closest point: depth-first, nearer child first, pruning nodes whose
/// f64 box is not closer than the best triangle so far. Exact in the sense that the
/// returned squared distance is the minimum over triangles of the f64 point-triangle
/// squared distance ([`closest_point_triangle`], Ericson 2005).
///
/// - `q`: query point, mesh frame.
/// - `hint`: a slot whose triangle is likely close (e.g. the previous query's), used as
///   the initial bound; any slot gives the same distance.
/// - `stack`: reusable stack of (node, squared box distance), cleared on entry.
///
/// # Complexity
/// O(log F) expected for well-shaped meshes, O(F) worst case.
pub(crate) fn closest_point_slot(
    bvh: &TriangleBvh,
    q: V3,
    hint: Option<u32>,
    stack: &mut Vec<(u32, f64)>,
) -> (ClosestPoint, u32) {
    let boxes = &bvh.hot_boxes[..];
    let corners = &bvh.corners[..];
    let planes = &bvh.planes[..];
    stack.clear();
    stack.push((0, box_distance_squared(q, boxes[0].lo, boxes[0].hi)));
    let mut best_d2 = f64::INFINITY;
    let mut best_point = [f64::NAN; 3];
    let mut best_slot = u32::MAX;
    if let Some(s) = hint.filter(|&s| (s as usize) < corners.len()) {
        let t = &corners[s as usize];
        best_point = closest_point_triangle(q, t[0], t[1], t[2]);
        best_d2 = norm_squared(sub(q, best_point));
        best_slot = s;
    }
    while let Some((n, lower)) = stack.pop() {
        if lower > best_d2 {
            continue;
        }
        let link = boxes[n as usize].link;
        if link[1] != u32::MAX {
            for s in link[0]..link[1] {
                // Cheap lower bound first: the distance to the triangle's plane. The
                // relative slack keeps rounding from skipping a triangle that ties.
                let pl = &planes[s as usize];
                let h = pl[0] * q[0] + pl[1] * q[1] + pl[2] * q[2] - pl[3];
                if h * h > best_d2 * (1.0 + 1e-9) {
                    continue;
                }
                let t = &corners[s as usize];
                let c = closest_point_triangle(q, t[0], t[1], t[2]);
                let d2 = norm_squared(sub(q, c));
                if d2 < best_d2 {
                    best_d2 = d2;
                    best_point = c;
                    best_slot = s;
                }
            }
        } else {
            let l = link[0];
            let r = l + 1;
            let (bl, br) = (&boxes[l as usize], &boxes[r as usize]);
            let dl = box_distance_squared(q, bl.lo, bl.hi);
            let dr = box_distance_squared(q, br.lo, br.hi);
            // Push the farther child first so the nearer one is explored first.
            let (near, dn, far, df) = if dl <= dr { (l, dl, r, dr) } else { (r, dr, l, dl) };
            if df <= best_d2 {
                stack.push((far, df));
            }
            if dn <= best_d2 {
                stack.push((near, dn));
            }
        }
    }
    let c = ClosestPoint { point: best_point, squared_distance: best_d2, triangle: bvh.tri_ids[best_slot as usize] };
    (c, best_slot)
}
