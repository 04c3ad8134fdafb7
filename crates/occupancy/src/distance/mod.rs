//! Exact closest points and distances to the mesh.

pub mod closest_point_triangle;

use crate::bvh::TriangleBvh;
use closest_point_triangle::closest_point_triangle;
use vf_common::vec3::{box_distance_squared, norm_squared, sub, V3};

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

impl TriangleBvh {
    /// Builds a BVH for closest-point queries only, without the winding-number data of
    /// [`crate::MeshOracle`] (faster to build; used by the `metrics` crate).
    ///
    /// - `positions`: #V×3 f64, any frame; every coordinate finite with magnitude ≤
    ///   [`crate::MAX_COORDINATE`].
    /// - `triangles`: #F×3 u32 zero-based; degenerate and duplicate triangles accepted.
    /// - `config`: only `bvh_preset` and `max_leaf_size` are used.
    ///
    /// # Errors
    /// As [`crate::MeshOracle::new`]: [`crate::OccupancyError::NoTriangles`],
    /// [`crate::OccupancyError::VertexOutOfRange`], [`crate::OccupancyError::BadVertex`],
    /// [`crate::OccupancyError::BadConfig`].
    pub fn for_distance(
        positions: &[[f64; 3]],
        triangles: &[[u32; 3]],
        config: &crate::Config,
    ) -> Result<TriangleBvh, crate::OccupancyError> {
        use crate::OccupancyError;
        config.validate()?;
        if triangles.is_empty() {
            return Err(OccupancyError::NoTriangles);
        }
        let limit = crate::MAX_COORDINATE;
        for (vertex, p) in positions.iter().enumerate() {
            if let Some(&value) = p.iter().find(|x| !(x.is_finite() && x.abs() <= limit)) {
                return Err(OccupancyError::BadVertex { vertex, value, limit });
            }
        }
        let num_vertices = positions.len();
        let mut corners = Vec::with_capacity(triangles.len());
        for (triangle, t) in triangles.iter().enumerate() {
            for &vertex in t {
                if vertex as usize >= num_vertices {
                    return Err(OccupancyError::VertexOutOfRange { triangle, vertex, num_vertices });
                }
            }
            corners.push([positions[t[0] as usize], positions[t[1] as usize], positions[t[2] as usize]]);
        }
        Ok(crate::bvh::build_triangle_bvh(&corners, config.bvh_preset, config.max_leaf_size, config.max_leaf_size))
    }

    /// Closest point on the triangles to `q`: the same branch-and-bound and the same
    /// (bit-identical) answer as [`crate::MeshOracle::closest_point`]. Uses and updates
    /// `ws`'s previous-triangle hint.
    ///
    /// - `q`: query point, mesh frame, finite.
    pub fn closest_point(&self, q: V3, ws: &mut crate::Workspace) -> ClosestPoint {
        let (c, slot) = closest_point_slot(self, q, ws.last_slot, &mut ws.nodes_with_bound);
        ws.last_slot = Some(slot);
        c
    }

    /// Tight f64 bounding box `(min, max)` of the triangles, mesh frame.
    pub fn bounding_box(&self) -> (V3, V3) {
        (self.box_lo[0], self.box_hi[0])
    }
}

#[cfg(test)]
mod tests {
    use crate::bvh::TriangleBvh;
    use crate::{Config, MeshOracle, Workspace};

    #[test]
    fn distance_only_bvh_matches_the_oracle() {
        let n = 9u32;
        let mut p = Vec::new();
        for i in 0..=n {
            for j in 0..=n {
                let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
                p.push([x, y, 0.3 * (4.0 * x).sin() * y]);
            }
        }
        let id = |i: u32, j: u32| i * (n + 1) + j;
        let mut t = Vec::new();
        for i in 0..n {
            for j in 0..n {
                t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let oracle = MeshOracle::new(&p, &t, &Config::default()).unwrap();
        let bvh = TriangleBvh::for_distance(&p, &t, &Config::default()).unwrap();
        assert_eq!(bvh.validate(), Ok(()));
        assert_eq!(bvh.bounding_box(), oracle.bounding_box());
        let (mut w1, mut w2) = (Workspace::new(), Workspace::new());
        for k in 0..500 {
            let f = k as f64;
            let q = [(f * 0.37).sin() * 1.5, (f * 0.71).cos() * 1.5, (f * 0.13).sin()];
            assert_eq!(bvh.closest_point(q, &mut w1), oracle.closest_point(q, &mut w2));
        }
        assert!(TriangleBvh::for_distance(&p, &[], &Config::default()).is_err());
        assert!(TriangleBvh::for_distance(&[[f64::NAN, 0.0, 0.0]], &[[0, 0, 0]], &Config::default()).is_err());
        assert!(TriangleBvh::for_distance(&p, &[[0, 1, 999]], &Config::default()).is_err());
    }
}
