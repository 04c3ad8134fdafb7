//! Building the crust from labelled sites.

use std::time::Instant;

use delaunay3::Delaunay3;
use mesh_io::TriMesh;

use crate::check::{check_crust, CrustCheck};
use crate::circumcenter::circumcenter;
use crate::error::CrustError;
use crate::resolve::{self, Target};

/// Where the crust lives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CrustConfig {
    /// Lower corner of the domain box (unit-cube coordinates). Default (0, 0, 0).
    pub box_lo: [f64; 3],
    /// Upper corner of the domain box. Default (1, 1, 1).
    pub box_hi: [f64; 3],
}

impl Default for CrustConfig {
    fn default() -> Self {
        CrustConfig { box_lo: [0.0; 3], box_hi: [1.0; 3] }
    }
}

/// What the extraction did, for reports.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CrustStats {
    /// Sites given (inside and outside).
    pub num_sites: usize,
    /// Sites labelled inside.
    pub num_inside: usize,
    /// Mirror images of inside sites added across the box faces (see [`Crust::extract`]).
    pub num_mirrors: usize,
    /// 1, or 2 when mirrors were needed.
    pub num_delaunay_passes: usize,
    /// Finite tetrahedra of the (last) Delaunay pass.
    pub num_finite_tets: usize,
    /// Voronoi faces in the crust (polygons before triangulation).
    pub num_polygons: usize,
    /// Distinct Voronoi vertices on the crust (after merging exactly cospherical
    /// tetrahedra).
    pub num_voronoi_vertices: usize,
    /// Extra vertex copies made where inside cells touch only along an edge or at a point.
    pub num_split_vertices: usize,
    /// Voronoi vertices merged into a neighbour because their rounded positions broke the
    /// crust (nearly degenerate sites; see [`Crust::extract`]). 0 almost always.
    pub num_merged_vertices: usize,
    /// The largest crust-edge length (max-norm) merged to repair rounding, 0 when none.
    pub merge_distance: f64,
    /// Wall time of the Delaunay passes.
    pub delaunay_seconds: f64,
    /// Wall time of the whole extraction, checks included.
    pub total_seconds: f64,
}

/// A crust: the Voronoi faces between inside and outside sites, clipped to the domain box.
pub struct Crust {
    /// The crust as a closed, oriented (normals from inside to outside sites), manifold
    /// triangle mesh, in the sites' frame. Empty when no site is inside.
    ///
    /// - `mesh.positions`: #V×3 f64 Voronoi vertices (circumcentres);
    /// - `mesh.triangles`: #F×3 u32, counter-clockwise seen from outside.
    pub mesh: TriMesh,
    /// What the extraction did.
    pub stats: CrustStats,
    /// The exact checker's report on `mesh` ([`crate::check::check_crust`]), which it
    /// passed: extraction checks what it returns.
    pub check: CrustCheck,
    /// The crust's polygons (Voronoi faces) as ids into `mesh.positions`, before
    /// triangulation: what [`crate::output::finalize`] rounds.
    pub(crate) faces: Vec<Vec<u32>>,
    /// The tetrahedralization and labels, kept for [`Crust::cells`].
    state: Option<State>,
}

struct State {
    dt: Delaunay3,
    /// Per Delaunay vertex: inside?
    inside: Vec<bool>,
    vv: VoronoiVertices,
}

/// Voronoi vertices: classes of finite tetrahedra sharing one circumsphere exactly,
/// computed on demand, each with one circumcentre.
struct VoronoiVertices {
    class_of_tet: Vec<u32>,
    positions: Vec<[f64; 3]>,
}

const NONE: u32 = u32::MAX;

/// The largest crust-edge length merged to repair rounding, relative to the crust's
/// largest extent: 2⁻²⁶ ≈ 1.5e-8, some ten million ulps of f64 and far above the clusters
/// of nearly cospherical sites (a few hundred ulps at most in the tests).
const MAX_MERGE: f64 = 1.0 / (1u64 << 26) as f64;

impl VoronoiVertices {
    fn new(num_tets: usize) -> Self {
        VoronoiVertices { class_of_tet: vec![NONE; num_tets], positions: Vec::new() }
    }

    /// The Voronoi vertex of finite tetrahedron `t`: its exactly-cospherical neighbours
    /// (exact in-sphere test on the input coordinates, without perturbation) share it.
    fn class_of(&mut self, dt: &Delaunay3, t: u32) -> Result<u32, CrustError> {
        let c = self.class_of_tet[t as usize];
        if c != NONE {
            return Ok(c);
        }
        let id = self.positions.len() as u32;
        let corners = dt.tet(t).map(|v| dt.vertex(v));
        let cc = circumcenter(corners[0], corners[1], corners[2], corners[3])
            .ok_or_else(|| CrustError::Internal(format!("finite tetrahedron {t} is flat")))?;
        self.positions.push(cc);
        self.class_of_tet[t as usize] = id;
        let mut stack = vec![t];
        while let Some(s) = stack.pop() {
            let sc = dt.tet(s).map(|v| coord(dt.vertex(v)));
            for i in 0..4 {
                let (n, j) = dt.neighbor(s, i);
                if dt.is_infinite(n) || self.class_of_tet[n as usize] != NONE {
                    continue;
                }
                let opposite = coord(dt.vertex(dt.tet(n)[j]));
                if robust::insphere(sc[0], sc[1], sc[2], sc[3], opposite) == 0.0 {
                    self.class_of_tet[n as usize] = id;
                    stack.push(n);
                }
            }
        }
        Ok(id)
    }
}

fn coord(p: [f64; 3]) -> robust::Coord3D<f64> {
    robust::Coord3D { x: p[0], y: p[1], z: p[2] }
}

impl Crust {
    /// Extract the crust of labelled sites.
    ///
    /// - `sites`: #K×3 f64, strictly inside the domain box (unit-cube coordinates by
    ///   default);
    /// - `inside`: #K bool, the label of each site. Coincident sites are merged and take
    ///   the label of the first of them.
    ///
    /// # Bounding (the choice made for unbounded cells)
    /// Cells are clipped to the box exactly by mirror sites: an inside site whose cell
    /// reaches past a box face gets its mirror image across that face as an extra outside
    /// site. Inside the box a mirror is never nearer than its original, so the diagram in
    /// the box is unchanged, and the bisector of a site and its mirror is the face plane
    /// itself: every inside cell becomes cell ∩ box, and the crust is the boundary of
    /// (union of inside cells) ∩ box. Which sites need mirrors is read off a first
    /// tetrahedralization (hull sites, or a circumcentre beyond a face); most shapes
    /// normalised with a margin need none, and then one tetrahedralization suffices.
    /// To make mirrors exact, the box and the sites are first snapped to a power-of-two
    /// grid (2^-51 for the unit cube; sites move by at most 2.2e-16): the crust is exactly
    /// that of the snapped sites, and box-face vertices are exactly shared.
    ///
    /// # Guarantees
    /// The mesh is closed (every edge in exactly two triangles, with opposite
    /// orientations), vertex-manifold (where inside cells touch only along an edge or at
    /// a point, vertices are split), consistently oriented with normals from inside to
    /// outside sites, and its volume equals the summed volume of the inside cells (up to
    /// the rounding below). [`crate::check::check_crust`] verifies all of it, including
    /// exact freedom from self-intersections, and extraction runs it on what it returns
    /// ([`Crust::check`]).
    ///
    /// # Nearly degenerate sites
    /// Exactly cospherical tetrahedra share one Voronoi vertex (exact in-sphere test).
    /// Nearly cospherical ones — mirrored pairs across a smooth surface are so by
    /// construction: any three pairs are cospherical in exact arithmetic, but not after
    /// their coordinates are rounded — have distinct Voronoi vertices a few ulps to a few
    /// hundred ulps apart, joined by tiny edges and sliver faces, and rounding those
    /// vertices to f64 can make triangles cross or fold. When the exact check fails, the
    /// crust vertices around the faulty triangles that are joined by crust edges no longer
    /// than a growing distance (0, then 1, 4, 16, … units in the last place) are merged —
    /// the degenerate vertex the sites nearly have — and the polygons rebuilt, until the
    /// check passes (see `src/resolve.rs`). Sites never move; [`CrustStats`] counts the
    /// merged vertices.
    ///
    /// # Complexity
    /// One or two Delaunay tetrahedralizations, then O(crust size) plus the circumcentres
    /// of the tetrahedra around inside sites near the box faces, and the exact check of
    /// the result (about 20% of the total on uniform sites).
    ///
    /// # Errors
    /// Mismatched lengths, NaN, sites not strictly inside the box, a bad box; an internal
    /// error rather than an invalid mesh if a guarantee fails to hold.
    pub fn extract(sites: &[[f64; 3]], inside: &[bool], config: &CrustConfig) -> Result<Crust, CrustError> {
        let start = Instant::now();
        check_inputs(sites, inside, config)?;
        let (sites, config) = &snap_to_grid(sites, config)?;
        let sites = sites.as_slice();
        let mut stats = CrustStats {
            num_sites: sites.len(),
            num_inside: inside.iter().filter(|&&b| b).count(),
            ..Default::default()
        };
        if stats.num_inside == 0 {
            stats.total_seconds = start.elapsed().as_secs_f64();
            let mesh = TriMesh::default();
            let check = check_crust(&mesh).map_err(CrustError::Internal)?;
            return Ok(Crust { mesh, stats, check, faces: Vec::new(), state: None });
        }

        // Pass 1: which inside cells reach past which box faces.
        let t0 = Instant::now();
        let first = match Delaunay3::new(sites) {
            Ok(dt) => Some(dt),
            Err(delaunay3::DelaunayError::Degenerate { .. }) => None, // fewer than 4 independent sites
            Err(e) => return Err(e.into()),
        };
        stats.delaunay_seconds += t0.elapsed().as_secs_f64();
        stats.num_delaunay_passes = 1;
        let faces = match &first {
            Some(dt) => faces_crossed(dt, sites, inside, config)?,
            None => inside.iter().map(|&b| if b { 0b11_1111 } else { 0 }).collect(),
        };
        let mut all_sites = sites.to_vec();
        for (i, &mask) in faces.iter().enumerate() {
            for f in 0..6 {
                if mask & (1 << f) != 0 {
                    let (axis, hi) = (f / 2, f % 2 == 1);
                    let plane = if hi { config.box_hi[axis] } else { config.box_lo[axis] };
                    let mut m = sites[i];
                    m[axis] = 2.0 * plane - m[axis];
                    all_sites.push(m);
                }
            }
        }
        stats.num_mirrors = all_sites.len() - sites.len();
        let dt = if stats.num_mirrors == 0 {
            first.ok_or_else(|| CrustError::Internal("degenerate sites without mirrors".into()))?
        } else {
            let t0 = Instant::now();
            drop(first);
            let dt = Delaunay3::new(&all_sites)?;
            stats.delaunay_seconds += t0.elapsed().as_secs_f64();
            stats.num_delaunay_passes = 2;
            dt
        };
        stats.num_finite_tets = dt.num_finite_tets();
        let vertex_inside: Vec<bool> = (0..dt.num_vertices() as u32)
            .map(|v| {
                let i = dt.input_of_vertex(v) as usize;
                i < sites.len() && inside[i]
            })
            .collect();

        let mut vv = VoronoiVertices::new(dt.num_tets());
        let mut polygons: Vec<Vec<u32>> = Vec::new();
        let mut ring = Vec::new();
        // Bichromatic edges, found from the stars of the inside vertices only.
        let stars = dt.vertex_tets();
        let mut seen_from = vec![u32::MAX; dt.num_vertices()];
        for a in (0..dt.num_vertices() as u32).filter(|&v| vertex_inside[v as usize]) {
            for &t in stars.of(a) {
                for b in dt.tet(t) {
                    if b == delaunay3::INFINITE || vertex_inside[b as usize] || seen_from[b as usize] == a {
                        continue;
                    }
                    seen_from[b as usize] = a;
                    if let Some(poly) = face_polygon(&dt, &mut vv, t, a, b, true, &mut ring)? {
                        polygons.push(poly);
                    }
                }
            }
        }
        stats.num_polygons = polygons.len();
        // The vertices are rounded circumcentres: check the mesh exactly, and where
        // rounding broke it (nearly degenerate sites), merge what f64 cannot keep apart.
        let target = Target { round: |x| x, epsilon: f64::EPSILON, distinct_positions: false, max_merge: MAX_MERGE };
        let (built, check) = match resolve::attempt(&polygons, &vv.positions, &target) {
            Ok((built, check, _)) => (built, check),
            Err(first) => {
                let o = resolve::resolve(&polygons, &vv.positions, &target, first, None)?;
                stats.num_merged_vertices = o.num_merged;
                stats.merge_distance = o.merge_distance;
                (o.built, o.check)
            }
        };
        stats.num_voronoi_vertices = built.num_used;
        stats.num_split_vertices = built.num_split;
        stats.total_seconds = start.elapsed().as_secs_f64();
        let faces = built.faces;
        Ok(Crust { mesh: built.mesh, stats, check, faces, state: Some(State { dt, inside: vertex_inside, vv }) })
    }

    /// Every inside cell (clipped to the box) as a closed convex polyhedron, fan
    /// triangulated, counter-clockwise seen from outside, in the sites' frame, with the
    /// index of its site. Coincident sites share one cell, listed under the first.
    ///
    /// # Errors
    /// An internal error if a cell is unbounded (it cannot be, after mirroring).
    pub fn cells(&mut self) -> Result<Vec<(usize, TriMesh)>, CrustError> {
        let Some(state) = &mut self.state else { return Ok(Vec::new()) };
        let dt = &state.dt;
        let mut per_vertex: Vec<Vec<Vec<u32>>> = vec![Vec::new(); dt.num_vertices()];
        let mut ring = Vec::new();
        for e in dt.edges() {
            let [a, b] = e.vertices;
            for (me, inside_me) in [(a, true), (b, false)] {
                if !state.inside[me as usize] {
                    continue;
                }
                // Oriented outward from `me`: the face's normal points from a to b when
                // seen as a's face, so b's copy is reversed.
                if let Some(p) = face_polygon(dt, &mut state.vv, e.tet, a, b, inside_me, &mut ring)? {
                    per_vertex[me as usize].push(p);
                }
            }
        }
        let mut out = Vec::new();
        for (v, polys) in per_vertex.into_iter().enumerate() {
            if !state.inside[v] {
                continue;
            }
            let mut local = std::collections::HashMap::new();
            let mut mesh = TriMesh::default();
            for p in &polys {
                let ids: Vec<u32> = p
                    .iter()
                    .map(|&c| {
                        *local.entry(c).or_insert_with(|| {
                            mesh.positions.push(state.vv.positions[c as usize]);
                            mesh.positions.len() as u32 - 1
                        })
                    })
                    .collect();
                for k in 1..ids.len() - 1 {
                    mesh.triangles.push([ids[0], ids[k], ids[k + 1]]);
                }
            }
            out.push((dt.input_of_vertex(v as u32) as usize, mesh));
        }
        out.sort_by_key(|(i, _)| *i);
        Ok(out)
    }
}

/// The Voronoi face dual to Delaunay edge (a, b) as Voronoi-vertex ids, with consecutive
/// repeats (exactly cospherical tetrahedra) removed; oriented with its normal from a to b
/// if `a_is_inside`, else from b to a. `None` when it degenerates to a point or segment.
fn face_polygon(
    dt: &Delaunay3,
    vv: &mut VoronoiVertices,
    tet: u32,
    a: u32,
    b: u32,
    a_is_inside: bool,
    ring: &mut Vec<u32>,
) -> Result<Option<Vec<u32>>, CrustError> {
    dt.tets_around_edge(tet, a, b, ring);
    let mut poly: Vec<u32> = Vec::with_capacity(ring.len());
    for &t in ring.iter() {
        if dt.is_infinite(t) {
            return Err(CrustError::Internal(format!(
                "the Voronoi face between sites {} and {} is unbounded",
                dt.input_of_vertex(a),
                dt.input_of_vertex(b)
            )));
        }
        let c = vv.class_of(dt, t)?;
        if poly.last() != Some(&c) {
            poly.push(c);
        }
    }
    while poly.len() > 1 && poly.first() == poly.last() {
        poly.pop();
    }
    if poly.len() < 3 {
        return Ok(None);
    }
    // `tets_around_edge` turns positively about a → b, so the polygon's normal points from
    // a to b.
    if !a_is_inside {
        poly.reverse();
    }
    Ok(Some(poly))
}

pub(crate) fn check_inputs(sites: &[[f64; 3]], inside: &[bool], config: &CrustConfig) -> Result<(), CrustError> {
    if sites.len() != inside.len() {
        return Err(CrustError::LengthMismatch { num_sites: sites.len(), num_labels: inside.len() });
    }
    let (lo, hi) = (config.box_lo, config.box_hi);
    if (0..3).any(|k| !(lo[k].is_finite() && hi[k].is_finite() && lo[k] < hi[k])) {
        return Err(CrustError::BadBox { lo, hi });
    }
    for (index, p) in sites.iter().enumerate() {
        if p.iter().any(|c| !c.is_finite()) {
            return Err(CrustError::NonFinite { index, position: *p });
        }
        if (0..3).any(|k| !(p[k] > lo[k] && p[k] < hi[k])) {
            return Err(CrustError::OutsideBox { index, position: *p, lo, hi });
        }
    }
    Ok(())
}

/// Circumcentre in plain f64, trusted only when the tetrahedron is well shaped: `None`
/// when |det| < 2⁻²⁰·‖u‖‖v‖‖w‖ (then its error bound could exceed the 1e-6 margin used by
/// the caller). For a well-shaped tetrahedron of unit-cube sites the f64 error is below
/// 1e-9, far inside that margin.
fn circumcenter_f64(c: [[f64; 3]; 4]) -> Option<[f64; 3]> {
    let d = |p: [f64; 3]| [p[0] - c[0][0], p[1] - c[0][1], p[2] - c[0][2]];
    let (u, v, w) = (d(c[1]), d(c[2]), d(c[3]));
    let cross =
        |a: [f64; 3], b: [f64; 3]| [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let (vw, wu, uv) = (cross(v, w), cross(w, u), cross(u, v));
    let det = dot(u, vw);
    let (nu, nv, nw) = (dot(u, u), dot(v, v), dot(w, w));
    if !(det.abs() > 2f64.powi(-20) * (nu * nv * nw).sqrt()) {
        return None;
    }
    Some([0, 1, 2].map(|k| c[0][k] + (nu * vw[k] + nv * wu[k] + nw * uv[k]) / (2.0 * det)))
}

/// Snap the box and the sites to a grid of spacing g = 2^(e − 51), with 2^e the smallest
/// power of two above every |coordinate| of the box, so that every mirror `2·plane − x`
/// is exact: plane and x are multiples of g and |2·plane − x| < 2^(e+2) needs no more
/// than 53 bits. Exact mirrors keep the cospherical configurations of a site, its mirror
/// and their neighbours exactly cospherical, so box-face vertices merge exactly instead
/// of splitting into ulp-sized slivers. Sites move by at most g/2 (2^-52 ≈ 2.2e-16 in the
/// unit cube).
pub(crate) fn snap_to_grid(
    sites: &[[f64; 3]],
    config: &CrustConfig,
) -> Result<(Vec<[f64; 3]>, CrustConfig), CrustError> {
    let m = config.box_lo.iter().chain(&config.box_hi).fold(0.0f64, |a, &b| a.max(b.abs()));
    let e = if m == 0.0 { 0 } else { m.log2().floor() as i32 + 1 };
    let g = 2f64.powi(e - 51);
    let snap = |x: f64| (x / g).round() * g;
    let snapped = CrustConfig { box_lo: config.box_lo.map(snap), box_hi: config.box_hi.map(snap) };
    let out: Vec<[f64; 3]> = sites.iter().map(|p| p.map(snap)).collect();
    check_inputs(&out, &vec![false; out.len()], &snapped)?;
    Ok((out, snapped))
}

/// For each input site, a 6-bit mask of the box faces (bit 2·axis + (0 low, 1 high)) its
/// cell reaches past: all six for sites on the convex hull (unbounded cells), else those
/// beyond which one of its Voronoi vertices lies. Only inside sites need mirrors.
fn faces_crossed(
    dt: &Delaunay3,
    sites: &[[f64; 3]],
    inside: &[bool],
    config: &CrustConfig,
) -> Result<Vec<u8>, CrustError> {
    let nv = dt.num_vertices();
    let mut mask = vec![0u8; nv];
    for t in dt.infinite_tets() {
        for &v in &t[..3] {
            mask[v as usize] = 0b11_1111;
        }
    }
    let vertex_inside: Vec<bool> = (0..nv as u32).map(|v| inside[dt.input_of_vertex(v) as usize]).collect();
    for (t, verts) in dt.finite_tets().enumerate() {
        if !verts.iter().any(|&v| vertex_inside[v as usize]) {
            continue;
        }
        let c = verts.map(|v| dt.vertex(v));
        // A plain f64 circumcentre decides the clear cases; the double-double one is
        // computed where the f64 result is near a face or not trustworthy.
        let quick = circumcenter_f64(c);
        let clear = quick.is_some_and(|q| {
            (0..3).all(|k| {
                let margin = 1e-6 * (config.box_hi[k] - config.box_lo[k]);
                q[k] > config.box_lo[k] + margin && q[k] < config.box_hi[k] - margin
            })
        });
        if clear {
            continue;
        }
        let Some(cc) = circumcenter(c[0], c[1], c[2], c[3]) else {
            return Err(CrustError::Internal(format!("finite tetrahedron {t} is flat")));
        };
        let mut m = 0u8;
        for k in 0..3 {
            // Conservative: a centre on or near a face counts as crossing it (an extra
            // mirror is harmless; a missing one is not).
            let tol = 1e-9 * (config.box_hi[k] - config.box_lo[k]);
            if cc[k] <= config.box_lo[k] + tol {
                m |= 1 << (2 * k);
            }
            if cc[k] >= config.box_hi[k] - tol {
                m |= 1 << (2 * k + 1);
            }
        }
        if m != 0 {
            for v in verts {
                mask[v as usize] |= m;
            }
        }
    }
    let mut out = vec![0u8; sites.len()];
    for (i, o) in out.iter_mut().enumerate() {
        if inside[i] {
            *o = mask[dt.vertex_of_input(i) as usize];
        }
    }
    Ok(out)
}
