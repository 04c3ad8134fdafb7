//! The entry type: [`MeshOracle`], answering winding-number, occupancy and distance
//! queries about one triangle mesh.

use std::f64::consts::PI;

use rayon::prelude::*;

use crate::bvh::{build_triangle_bvh, TriangleBvh};
use crate::config::{Config, MAX_COORDINATE};
use crate::distance::{closest_point_slot, ClosestPoint};
use crate::order::morton_order;
use crate::winding::crossing::{crossing_winding, degenerate_slots, Crossing};
use crate::winding::exact::{build_caps, exact_solid_angle_sum, exact_traversal_counts, Caps};
use crate::winding::fast::{
    build_fast_nodes, fast_solid_angle_sum, fast_solid_angle_sums, fast_traversal_counts, FastNodes,
};
use crate::winding::WindingMode;
use crate::{OccupancyError, Workspace};
use vf_common::vec3::{cross, dot, sub, V3};

/// Number of queries per rayon task in the batch functions. Fixed, so the work split
/// never depends on the thread count (results never do either: queries are independent).
pub const QUERY_CHUNK: usize = 1024;

const INV_FOUR_PI: f64 = 1.0 / (4.0 * PI);

/// Occupancy, winding-number and distance oracle for one triangle mesh (closed, open,
/// non-manifold or a soup).
///
/// Holds the f64 triangles, an obvhs BVH with per-node f64 boxes, the Barill et al. 2018
/// expansions and the boundary caps of the hierarchical exact winding number.
///
/// # Example
/// ```
/// use occupancy::{Config, MeshOracle, WindingMode, Workspace};
/// // A tetrahedron, counter-clockwise seen from outside.
/// let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let triangles = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
/// let oracle = MeshOracle::new(&positions, &triangles, &Config::default())?;
/// let mut ws = Workspace::new();
/// let w = oracle.winding_number([0.1, 0.1, 0.1], WindingMode::Exact, &mut ws);
/// assert!((w - 1.0).abs() < 1e-12);
/// let d = oracle.signed_distance([0.1, 0.1, 0.1], WindingMode::Fast, &mut ws);
/// assert!((d + 0.1).abs() < 1e-12);
/// # Ok::<(), occupancy::OccupancyError>(())
/// ```
#[derive(Clone)]
pub struct MeshOracle {
    config: Config,
    bvh: TriangleBvh,
    fast: FastNodes,
    caps: Caps,
    /// Per slot, whether the triangle has zero area; empty unless the mesh is closed (then
    /// [`MeshOracle::inside`] counts crossings).
    degenerate: Vec<bool>,
    padding_squared: f64,
    num_vertices: usize,
    /// The β the fast winding number's nodes were built with ([`effective_beta`]).
    beta: f64,
}

/// Results of [`MeshOracle::query`] for #Q queries, in the queries' (mesh) frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct QueryBatch {
    /// #Q f64 generalized winding numbers.
    pub winding: Vec<f64>,
    /// #Q u8 occupancy: 1 when |winding| ≥ `Config::occupancy_threshold`
    /// ([`Config::is_inside_winding`]), else 0.
    pub occupancy: Vec<u8>,
    /// #Q f64 signed distances, mesh units: negative inside (occupancy 1), positive outside.
    pub sdf: Vec<f64>,
    /// #Q×3 f64 closest points on the mesh, mesh frame.
    pub closest: Vec<V3>,
    /// #Q f64 squared unsigned distances, mesh units².
    pub squared_distance: Vec<f64>,
    /// #Q u32 index of the input triangle holding each closest point.
    pub triangle: Vec<u32>,
    /// Number of fast-mode queries recomputed exactly near the threshold.
    pub num_exact_fallbacks: u64,
}

fn check_point(p: &V3) -> Option<f64> {
    p.iter().copied().find(|x| !(x.is_finite() && x.abs() <= MAX_COORDINATE))
}

/// Checks that every query coordinate is finite and at most [`MAX_COORDINATE`] in
/// magnitude.
///
/// # Errors
/// [`OccupancyError::BadQuery`] naming the first bad point.
pub fn validate_queries(queries: &[V3]) -> Result<(), OccupancyError> {
    match queries.iter().enumerate().find_map(|(i, q)| check_point(q).map(|v| (i, v))) {
        Some((index, value)) => Err(OccupancyError::BadQuery { index, value, limit: MAX_COORDINATE }),
        None => Ok(()),
    }
}

impl MeshOracle {
    /// Builds the oracle.
    ///
    /// - `positions`: #V×3 f64 vertex positions, any frame and units (queries and answers
    ///   use the same); every coordinate finite with magnitude ≤ [`MAX_COORDINATE`].
    /// - `triangles`: #F×3 u32 zero-based vertex indices; counter-clockwise seen from
    ///   outside for inside = positive winding. Degenerate, duplicate, non-manifold and
    ///   unoriented triangles are accepted (the winding number is meaningful for soups).
    /// - `config`: thresholds, see [`Config`].
    ///
    /// # Complexity
    /// O(F log F) time and O(F) memory (plus boundary caps, O(F) in practice).
    ///
    /// # Errors
    /// [`OccupancyError::NoTriangles`], [`OccupancyError::VertexOutOfRange`],
    /// [`OccupancyError::BadVertex`], [`OccupancyError::BadConfig`].
    pub fn new(positions: &[[f64; 3]], triangles: &[[u32; 3]], config: &Config) -> Result<Self, OccupancyError> {
        config.validate()?;
        if triangles.is_empty() {
            return Err(OccupancyError::NoTriangles);
        }
        for (vertex, p) in positions.iter().enumerate() {
            if let Some(value) = check_point(p) {
                return Err(OccupancyError::BadVertex { vertex, value, limit: MAX_COORDINATE });
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
        let bvh = build_triangle_bvh(
            &corners,
            config.bvh_preset,
            config.winding_leaf_size.min(config.max_leaf_size),
            config.max_leaf_size,
        );
        debug_assert_eq!(bvh.validate(), Ok(()));
        let beta = effective_beta(config.beta, &corners);
        let fast = build_fast_nodes(&bvh, beta);
        let caps = build_caps(&bvh);
        let (lo, hi) = (bvh.box_lo[0], bvh.box_hi[0]);
        let diag2: f64 = (0..3).map(|k| (hi[k] - lo[k]) * (hi[k] - lo[k])).sum();
        let padding_squared = config.cap_box_padding * config.cap_box_padding * diag2;
        let degenerate = if caps.is_closed() { degenerate_slots(&bvh) } else { Vec::new() };
        Ok(MeshOracle { config: config.clone(), bvh, fast, caps, degenerate, padding_squared, num_vertices, beta })
    }

    /// Builds the oracle for a [`mesh_io::TriMesh`] (see [`MeshOracle::new`] for the
    /// conventions, errors and complexity).
    ///
    /// # Errors
    /// As [`MeshOracle::new`].
    pub fn from_mesh(mesh: &mesh_io::TriMesh, config: &Config) -> Result<Self, OccupancyError> {
        Self::new(&mesh.positions, &mesh.triangles, config)
    }

    /// The configuration this oracle was built with.
    pub fn config(&self) -> &Config {
        &self.config
    }

    /// The β the fast winding number uses on this mesh: `Config::beta`, raised on meshes
    /// with much surface for their box (see [`effective_beta`]).
    pub fn beta(&self) -> f64 {
        self.beta
    }

    /// Number of input vertices.
    pub fn num_vertices(&self) -> usize {
        self.num_vertices
    }

    /// Number of input triangles.
    pub fn num_triangles(&self) -> usize {
        self.bvh.num_triangles()
    }

    /// The BVH (for inspection and `validate()`).
    pub fn bvh(&self) -> &TriangleBvh {
        &self.bvh
    }

    /// Tight f64 bounding box `(min, max)` of the mesh, mesh frame.
    pub fn bounding_box(&self) -> (V3, V3) {
        (self.bvh.box_lo[0], self.bvh.box_hi[0])
    }

    /// Checks the oracle's invariants completely: the BVH ([`TriangleBvh::validate`]), the
    /// per-node arrays' lengths, the caps' ranges, and that every stored cap is closed up
    /// with its node's triangles (the boundary of the fan equals the boundary of the
    /// patch, checked as a chain on welded vertices).
    ///
    /// # Errors
    /// A description of the first violated invariant.
    pub fn validate(&self) -> Result<(), String> {
        self.bvh.validate()?;
        let num_nodes = self.bvh.num_nodes();
        if self.fast.hot.len() != num_nodes
            || self.fast.moments.len() != num_nodes
            || self.caps.start.len() != num_nodes
            || self.caps.len.len() != num_nodes
        {
            return Err("per-node arrays differ in length from the BVH".into());
        }
        for n in 0..num_nodes {
            let start = self.caps.start[n];
            if start != u32::MAX && start as usize + self.caps.len[n] as usize > self.caps.edges.len() {
                return Err(format!("cap of node {n} runs past the edge list"));
            }
        }
        crate::winding::exact::check_caps(&self.bvh, &self.caps)
    }

    /// Number of stored boundary-cap edges of the exact hierarchical winding number.
    pub fn num_cap_edges(&self) -> usize {
        self.caps.edges.len()
    }

    /// Exact generalized winding number at `q` (Jacobson et al. 2013): the sum of the
    /// triangles' signed solid angles over 4π, organised hierarchically with boundary caps.
    ///
    /// - `q`: query point, mesh frame, finite.
    pub fn winding_number_exact(&self, q: V3, ws: &mut Workspace) -> f64 {
        exact_solid_angle_sum(&self.bvh, &self.caps, q, self.padding_squared, &mut ws.nodes) * INV_FOUR_PI
    }

    /// Fast winding number (Barill et al. 2018) *without* the exact fallback: the raw
    /// approximation, for measuring its error.
    ///
    /// - `q`: query point, mesh frame, finite.
    pub fn winding_number_fast_unguarded(&self, q: V3, ws: &mut Workspace) -> f64 {
        fast_solid_angle_sum(&self.bvh, &self.fast, q, &mut ws.nodes) * INV_FOUR_PI
    }

    /// Work counters of one winding query, for profiling: `[nodes visited, expansions or
    /// cap triangles, mesh triangles summed exactly]`.
    pub fn winding_work(&self, q: V3, mode: WindingMode, ws: &mut Workspace) -> [u64; 3] {
        match mode {
            WindingMode::Exact => exact_traversal_counts(&self.bvh, &self.caps, q, self.padding_squared, &mut ws.nodes),
            WindingMode::Fast => fast_traversal_counts(&self.bvh, &self.fast, q, &mut ws.nodes),
        }
    }

    /// Generalized winding number at `q`.
    ///
    /// In [`WindingMode::Fast`], a value whose magnitude is within
    /// `Config::exact_fallback_margin` of `Config::occupancy_threshold` (either sign:
    /// [`Config::needs_exact_fallback`]) is recomputed exactly (counted in
    /// `ws.num_exact_fallbacks`), so inside/outside never flips relative to the exact mode
    /// while the approximation error stays below the margin.
    ///
    /// - `q`: query point, mesh frame, finite.
    pub fn winding_number(&self, q: V3, mode: WindingMode, ws: &mut Workspace) -> f64 {
        match mode {
            WindingMode::Exact => self.winding_number_exact(q, ws),
            WindingMode::Fast => {
                let w = self.winding_number_fast_unguarded(q, ws);
                self.guard(q, w, ws)
            }
        }
    }

    /// The exact fallback of the fast mode: `w` (a fast value at `q`) itself, or the exact
    /// winding number when `w` is too close to the threshold to decide from.
    fn guard(&self, q: V3, w: f64, ws: &mut Workspace) -> f64 {
        if self.config.needs_exact_fallback(w) {
            ws.num_exact_fallbacks += 1;
            self.winding_number_exact(q, ws)
        } else {
            w
        }
    }

    /// Whether `q` is inside: |winding number| ≥ `Config::occupancy_threshold`
    /// ([`Config::is_inside_winding`], the workspace's one rule).
    pub fn is_inside(&self, q: V3, mode: WindingMode, ws: &mut Workspace) -> bool {
        self.config.is_inside_winding(self.winding_number(q, mode, ws))
    }

    /// [`MeshOracle::is_inside`] for many points, in parallel fixed-size chunks (fast mode
    /// with the exact fallback): #Q booleans in query order.
    ///
    /// # Errors
    /// A query that is not finite.
    pub fn inside(&self, queries: &[V3]) -> Result<Vec<bool>, OccupancyError> {
        if self.is_closed() {
            validate_queries(queries)?;
            return Ok(self.inside_by_crossings(queries));
        }
        self.inside_by_winding(queries)
    }

    /// Whether the mesh is closed (its oriented edges cancel on welded vertices): then
    /// [`MeshOracle::inside`] counts the crossings of a segment to the outside
    /// ([`crate::winding::crossing`]) instead of summing solid angles.
    pub fn is_closed(&self) -> bool {
        self.caps.is_closed()
    }

    /// [`MeshOracle::inside`] on a closed mesh: exact integer winding numbers by crossing
    /// counts; a query on a triangle, or one whose every direction is degenerate, takes the
    /// exact solid-angle sum instead. The labels equal the solid-angle path's.
    pub fn inside_by_crossings(&self, queries: &[V3]) -> Vec<bool> {
        queries
            .par_chunks(QUERY_CHUNK)
            .flat_map_iter(|chunk| {
                let mut stack = Vec::new();
                let mut ws = Workspace::new();
                chunk
                    .iter()
                    .map(|&q| match crossing_winding(&self.bvh, &self.degenerate, q, &mut stack) {
                        Crossing::Winding(w) => self.config.is_inside_winding(w as f64),
                        Crossing::OnSurface | Crossing::Degenerate => {
                            self.config.is_inside_winding(self.winding_number_exact(q, &mut ws))
                        }
                    })
                    .collect::<Vec<_>>()
            })
            .collect()
    }

    /// [`MeshOracle::inside`] by the solid-angle sums (fast mode with the exact fallback),
    /// whether or not the mesh is closed: the reference the crossing count is tested against.
    ///
    /// # Errors
    /// A query that is not finite.
    pub fn inside_by_winding(&self, queries: &[V3]) -> Result<Vec<bool>, OccupancyError> {
        validate_queries(queries)?;
        Ok(self.map_coherent_winding(queries, WindingMode::Fast, |_, w, _| self.config.is_inside_winding(w)).0)
    }

    /// Closest point on the mesh to `q` (exact f64 point-triangle distances, BVH
    /// branch-and-bound).
    ///
    /// - `q`: query point, mesh frame, finite.
    pub fn closest_point(&self, q: V3, ws: &mut Workspace) -> ClosestPoint {
        let (c, slot) = closest_point_slot(&self.bvh, q, ws.last_slot, &mut ws.nodes_with_bound);
        ws.last_slot = Some(slot);
        c
    }

    /// Signed distance at `q`, mesh units: the unsigned distance to the mesh, negative
    /// inside (winding number ≥ threshold in `mode`), positive outside.
    pub fn signed_distance(&self, q: V3, mode: WindingMode, ws: &mut Workspace) -> f64 {
        let d = self.closest_point(q, ws).squared_distance.sqrt();
        if self.is_inside(q, mode, ws) {
            -d
        } else {
            d
        }
    }

    /// Winding numbers of many queries (parallel, deterministic).
    ///
    /// - `queries`: #Q×3 f64, mesh frame.
    /// - returns: #Q f64 winding numbers.
    ///
    /// # Errors
    /// [`OccupancyError::BadQuery`] for a non-finite or huge coordinate.
    pub fn winding_numbers(&self, queries: &[V3], mode: WindingMode) -> Result<Vec<f64>, OccupancyError> {
        Ok(self.winding_numbers_counted(queries, mode)?.0)
    }

    /// [`MeshOracle::winding_numbers`] with the number of queries that fell in the exact
    /// fallback band (fast mode; 0 in exact mode), for reporting the fallback share.
    ///
    /// # Errors
    /// [`OccupancyError::BadQuery`] for a non-finite or huge coordinate.
    pub fn winding_numbers_counted(
        &self,
        queries: &[V3],
        mode: WindingMode,
    ) -> Result<(Vec<f64>, u64), OccupancyError> {
        validate_queries(queries)?;
        Ok(self.map_coherent_winding(queries, mode, |_, w, _| w))
    }

    /// Closest points of many queries (parallel, deterministic).
    ///
    /// - `queries`: #Q×3 f64, mesh frame.
    /// - returns: #Q closest points.
    ///
    /// # Errors
    /// [`OccupancyError::BadQuery`] for a non-finite or huge coordinate.
    pub fn closest_points(&self, queries: &[V3]) -> Result<Vec<ClosestPoint>, OccupancyError> {
        validate_queries(queries)?;
        Ok(self.map_coherent(queries, |q, ws| self.closest_point(q, ws)).0)
    }

    /// Everything at once for many queries: winding number, occupancy, signed distance,
    /// closest point (parallel, deterministic).
    ///
    /// - `queries`: #Q×3 f64, mesh frame.
    ///
    /// # Errors
    /// [`OccupancyError::BadQuery`] for a non-finite or huge coordinate.
    pub fn query(&self, queries: &[V3], mode: WindingMode) -> Result<QueryBatch, OccupancyError> {
        validate_queries(queries)?;
        let (rows, fallbacks) = self.map_coherent_winding(queries, mode, |q, w, ws| (w, self.closest_point(q, ws)));
        let n = queries.len();
        let mut out = QueryBatch {
            num_exact_fallbacks: fallbacks,
            winding: Vec::with_capacity(n),
            occupancy: Vec::with_capacity(n),
            sdf: Vec::with_capacity(n),
            closest: Vec::with_capacity(n),
            squared_distance: Vec::with_capacity(n),
            triangle: Vec::with_capacity(n),
        };
        for (w, c) in rows {
            let inside = self.config.is_inside_winding(w);
            let d = c.squared_distance.sqrt();
            out.winding.push(w);
            out.occupancy.push(inside as u8);
            out.sdf.push(if inside { -d } else { d });
            out.closest.push(c.point);
            out.squared_distance.push(c.squared_distance);
            out.triangle.push(c.triangle);
        }
        Ok(out)
    }

    /// [`MeshOracle::map_coherent`] with the winding number of each query in `mode` passed
    /// to `f` as its second argument. In the fast mode the raw values come from the packet
    /// traversal ([`fast_solid_angle_sums`], bit-identical to one query at a time) over each
    /// chunk's Morton-ordered queries, then pass the exact fallback one by one.
    fn map_coherent_winding<T, F>(&self, queries: &[V3], mode: WindingMode, f: F) -> (Vec<T>, u64)
    where
        T: Send + Copy + Default,
        F: Fn(V3, f64, &mut Workspace) -> T + Sync,
    {
        match mode {
            WindingMode::Exact => self.map_coherent_chunks(queries, |idx, ws| {
                idx.iter()
                    .map(|&i| {
                        let q = queries[i as usize];
                        let w = self.winding_number_exact(q, ws);
                        f(q, w, ws)
                    })
                    .collect()
            }),
            WindingMode::Fast => self.map_coherent_chunks(queries, |idx, ws| {
                let pts: Vec<V3> = idx.iter().map(|&i| queries[i as usize]).collect();
                let mut raw = vec![0.0; pts.len()];
                fast_solid_angle_sums(&self.bvh, &self.fast, &pts, &mut raw, &mut ws.packets);
                pts.iter()
                    .zip(raw)
                    .map(|(&q, r)| {
                        let w = self.guard(q, r * INV_FOUR_PI, ws);
                        f(q, w, ws)
                    })
                    .collect()
            }),
        }
    }

    /// Applies `f` to every query in Morton order, in fixed chunks of [`QUERY_CHUNK`]
    /// processed in parallel with one fresh workspace state per chunk, and returns the
    /// results in input order with the number of exact fallbacks. The output does not
    /// depend on the thread count.
    fn map_coherent<T, F>(&self, queries: &[V3], f: F) -> (Vec<T>, u64)
    where
        T: Send + Copy + Default,
        F: Fn(V3, &mut Workspace) -> T + Sync,
    {
        self.map_coherent_chunks(queries, |idx, ws| idx.iter().map(|&i| f(queries[i as usize], ws)).collect())
    }

    /// The chunking of [`MeshOracle::map_coherent`]: `f` maps one chunk of Morton-ordered
    /// query indices to its results.
    fn map_coherent_chunks<T, F>(&self, queries: &[V3], f: F) -> (Vec<T>, u64)
    where
        T: Send + Copy + Default,
        F: Fn(&[u32], &mut Workspace) -> Vec<T> + Sync,
    {
        let order = morton_order(queries);
        let (sorted, fallbacks): (Vec<Vec<T>>, Vec<u64>) = order
            .par_chunks(QUERY_CHUNK)
            .map_init(Workspace::new, |ws, idx| {
                ws.last_slot = None;
                let before = ws.num_exact_fallbacks;
                let v = f(idx, ws);
                (v, ws.num_exact_fallbacks - before)
            })
            .unzip();
        let mut out = vec![T::default(); queries.len()];
        for (chunk, idx) in sorted.iter().zip(order.chunks(QUERY_CHUNK)) {
            for (v, &i) in chunk.iter().zip(idx) {
                out[i as usize] = *v;
            }
        }
        (out, fallbacks.iter().sum())
    }
}

/// The fast winding number's β for a mesh: `beta`·max(1, A/A_box)^¼, with A the mesh's
/// surface area and A_box its bounding box's.
///
/// Why: each node the traversal expands adds a truncation error of about its solid angle
/// seen from the query times (R/ρ)³ ≤ β⁻³, so a query's error grows with the summed
/// |solid angle| of the surface around it, that is with how many sheets of surface a ray
/// from it crosses. By Cauchy's formula a line through a convex box crosses a surface of
/// area A on average 2A/A_box times (the box itself: twice), so A/A_box measures that depth.
/// A single closed shape has A/A_box ≤ 1 (a ball 0.52, the bunny 0.46, a cube 1) and keeps
/// β; a mesh with nested or folded sheets gets a larger β. Measured
/// (`cargo run --release -p occupancy --example fast_on_files -- 100000 MESH`, issue
/// queries): the Menger sponge (A/A_box = 4.13) had max error 2.2e-3 (523 of 100k queries
/// above 1e-3) at β = 3.5 and 4.2e-4 (none) at β = 4.97, 1.6× the time per query; the
/// max error fell as about β^-4.6 there (1.0e-3 at 4, 6.5e-4 at 4.5), so the fourth root
/// keeps a margin. An exponent of 1/3 (β = 5.6) cost another 10% for 2.8e-4. Growing β only
/// for nodes with much area for their ball (area/πR² > 1) did little (2.2e-3 → 1.1e-3 even
/// at the first power): the error comes from many small nodes, each with little area.
/// The box is the mesh's axis-aligned one, so rotating a mesh lowers the ratio (by up to 3×).
pub fn effective_beta(beta: f64, corners: &[[V3; 3]]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut area = 0.0;
    for t in corners {
        for p in t {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let c = cross(sub(t[1], t[0]), sub(t[2], t[0]));
        area += 0.5 * dot(c, c).sqrt();
    }
    let e = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
    let box_area = 2.0 * (e[0] * e[1] + e[1] * e[2] + e[2] * e[0]);
    if !(box_area > 0.0 && area.is_finite()) {
        return beta;
    }
    beta * (area / box_area).max(1.0).powf(0.25)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 12×12 grid of an open height field: its BVH nodes have boundary caps.
    fn open_grid() -> (Vec<V3>, Vec<[u32; 3]>) {
        let n = 12u32;
        let mut p = Vec::new();
        for i in 0..=n {
            for j in 0..=n {
                let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
                p.push([x, y, 0.2 * (3.0 * x).sin() * y]);
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
        (p, t)
    }

    #[test]
    fn validate_catches_a_corrupted_cap() {
        let (p, t) = open_grid();
        let mut oracle = MeshOracle::new(&p, &t, &Config::default()).unwrap();
        assert_eq!(oracle.validate(), Ok(()));
        assert!(oracle.num_cap_edges() > 0);
        let e = oracle.caps.edges[0];
        oracle.caps.edges[0] = [e[1], e[0]];
        assert!(oracle.validate().is_err());
    }
}
