//! Closing an open mesh's planar holes flat, the way a person would.
//!
//! The workspace's solid is the generalized winding number's |w| ≥ 0.5. Across a hole of an
//! open mesh that solid is bounded by the |w| = 0.5 level set, a cap with no triangles of
//! its own: the fit finds points on it by Newton steps from its sample pool. For a single
//! planar hole in an otherwise closed surface the cap is the hole's flat lid (on the lid's
//! plane the missing lid would add exactly ±½), but with several holes each cap is pulled
//! by the others' missing lids and bends (an open pipe's two ends), and a sampled cap is
//! fitted less closely than a surface with triangles (a cube without its bottom at
//! K = 1,024: its crust is 2.1% of the diagonal from the closed cube with the cap, 0.33%
//! with the lid). A person closes such a hole with its flat lid. [`fill_planar_holes`] does
//! that, and nothing where the winding number is the better answer:
//!
//! - A hole is a loop of boundary edges (edges used by exactly one triangle, vertices
//!   identified by position). Loops are traced along the triangles' direction and split at
//!   vertices they pass twice (pinch vertices, where two holes touch), so every loop is a
//!   simple cycle of vertices; boundary edges that do not chain into a loop (a piece whose
//!   neighbours disagree on their orientation) are left alone.
//! - A loop is filled only when it is planar: a plane fitted to its vertices (principal
//!   components) holds each of them within [`PLANARITY_TOLERANCE`] of the loop's extent.
//!   A scan's holes, whose rims wander out of any plane, keep the winding number's cap.
//! - Its projection onto that plane must be a simple polygon (no crossing, no touching,
//!   checked by spade with exact predicates) of non-zero area; it is triangulated by a
//!   constrained Delaunay triangulation on the rim's own vertices (no new vertex), so the
//!   filled mesh is watertight across the rim, and oriented so that each rim edge is used
//!   once in each direction.
//! - The fill must close a piece with real volume ([`MIN_FILL_DEPTH`]): a flat patch's
//!   only loop is its own outline, planar and simple, and filling it would double the
//!   sheet; a soup's triangles are each their own planar loop.
//! - The fill must lie on the boundary of the solid it closes, where the open mesh's
//!   winding number is about ½ ([`LID_WINDING`]), not inside it or outside it.
//!
//! Positions are untouched and the input's triangles come first, in order; the fills are
//! appended.

use std::collections::{HashMap, VecDeque};

use serde::{Deserialize, Serialize};
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

use crate::dsu::Dsu;
use crate::TriMesh;

/// Largest distance of a rim vertex from the loop's fitted plane, as a share of the loop's
/// extent (the diagonal of its vertices' bounding box), for the loop to count as planar.
/// 1%: the fill then lies within 1% of the hole's size of where its rim is, below the
/// carving tolerance (0.3% of the mesh's diagonal) for any hole up to a third of the
/// mesh; a flat cut written with float rounding, or a CAD face lost in export, is planar to
/// 1e-6 or better, while the holes of scans wander by several percent (libigl's camelhead,
/// its neck cut: 4.5% of the loop's extent; on the real-world benchmark's car body the wheel
/// arches and windows are within 0.8%, its open underside 7.3%).
pub const PLANARITY_TOLERANCE: f64 = 0.01;

/// Least depth of the piece a fill closes for the fill to be made: the volume it encloses
/// (the loop's component with this loop filled and every other hole of the component
/// closed by a fan from its centroid) over the fill's area to the power 3/2. A cube closed
/// by its missing face: 1; a hemisphere by its disc: 0.38; a flat patch by its own outline,
/// or a soup's triangle by itself: 0. Below 0.05 the closed piece would be a lens or a slab
/// thinner than a twentieth of the hole's width: the mesh is a sheet with a shallow bend (a
/// plate, a terrain with a level rim), which the fill would turn into a thin slab of two
/// nearly coincident sheets.
pub const MIN_FILL_DEPTH: f64 = 0.05;

/// What [`fill_planar_holes`] fills.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FillOptions {
    /// [`PLANARITY_TOLERANCE`] by default.
    pub planarity: f64,
    /// [`MIN_FILL_DEPTH`] by default; 0 fills every planar simple loop, sheets' outlines
    /// included.
    pub min_depth: f64,
}

impl Default for FillOptions {
    fn default() -> Self {
        FillOptions { planarity: PLANARITY_TOLERANCE, min_depth: MIN_FILL_DEPTH }
    }
}

/// What [`fill_planar_holes`] found and did. Areas are in the mesh's units squared.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct HoleFilling {
    /// Boundary loops found (holes, and a sheet's outline).
    pub loops_found: usize,
    /// Loops closed by a flat fill.
    pub loops_filled: usize,
    /// Total area of the fills.
    pub filled_area: f64,
    /// Triangles added.
    pub triangles_added: usize,
    /// Loops left open because their rim is not planar ([`FillOptions::planarity`]).
    pub open_not_planar: usize,
    /// Loops left open because their projection crosses or touches itself.
    pub open_not_simple: usize,
    /// Loops left open because the fill would enclose no real volume
    /// ([`FillOptions::min_depth`]): a sheet's outline, a soup's triangle.
    pub open_shallow: usize,
    /// Loops left open because they have fewer than 3 vertices or no area.
    pub open_degenerate: usize,
    /// Loops left open because their lid would lie inside or outside the solid it closes,
    /// not on its boundary ([`LID_WINDING`]).
    pub open_not_on_boundary: usize,
    /// Loops left open because their piece (component) also has boundary edges on no
    /// loop: its volume, and so the fill's depth, is not defined.
    pub open_in_tangled_piece: usize,
    /// Boundary edges on no loop (they do not chain: neighbours disagree on orientation).
    pub untraced_boundary_edges: usize,
}

impl HoleFilling {
    /// Loops left open, for whatever reason.
    pub fn loops_open(&self) -> usize {
        self.loops_found - self.loops_filled
    }
}

/// `mesh` with its planar holes closed flat (module doc), and the account of it.
///
/// # Complexity
/// O(F) hashing, plus O(n log n) per loop of n vertices.
#[allow(clippy::neg_cmp_op_on_partial_ord, reason = "a NaN must fail these tests, and !(x > 0.0) holds for it")]
pub fn fill_planar_holes(mesh: &TriMesh, opts: &FillOptions) -> (TriMesh, HoleFilling) {
    let canon = weld_by_position(&mesh.positions);
    let welded: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .map(|t| t.map(|v| canon[v as usize]))
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
        .collect();
    let (loops, untraced) = boundary_loops(&welded);
    let mut report =
        HoleFilling { loops_found: loops.len(), untraced_boundary_edges: untraced.len(), ..Default::default() };
    let mut out = mesh.clone();
    if loops.is_empty() {
        return (out, report);
    }
    let p = &mesh.positions;
    // Components through shared (welded) vertices, each with a reference point for volumes.
    let mut dsu = Dsu::new(p.len());
    for t in &welded {
        dsu.union(t[0], t[1]);
        dsu.union(t[1], t[2]);
    }
    let tangled: std::collections::HashSet<u32> = untraced.iter().map(|&v| dsu.find(v)).collect();
    let mut reference: HashMap<u32, [f64; 3]> = HashMap::new();
    for l in &loops {
        reference.entry(dsu.find(l[0])).or_insert_with(|| centroid(p, l));
    }
    // Each component's volume with every hole closed by a fan from its centroid (the
    // components without a loop are not needed).
    let mut volume: HashMap<u32, f64> = HashMap::new();
    for t in &welded {
        let root = dsu.find(t[0]);
        if let Some(r) = reference.get(&root) {
            *volume.entry(root).or_insert(0.0) += tet(*r, p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]);
        }
    }
    let fans: Vec<f64> = loops
        .iter()
        .map(|l| {
            let r = reference[&dsu.find(l[0])];
            fan_volume(p, l, r)
        })
        .collect();
    for (l, f) in loops.iter().zip(&fans) {
        *volume.entry(dsu.find(l[0])).or_insert(0.0) += f;
    }
    // Lids that pass every test but the last, with their area.
    let mut candidates: Vec<(Vec<[u32; 3]>, f64)> = Vec::new();
    for (l, fan) in loops.iter().zip(&fans) {
        if tangled.contains(&dsu.find(l[0])) {
            report.open_in_tangled_piece += 1;
            continue;
        }
        match fill_loop(p, l, opts.planarity) {
            Fill::Degenerate => report.open_degenerate += 1,
            Fill::NotPlanar => report.open_not_planar += 1,
            Fill::NotSimple => report.open_not_simple += 1,
            Fill::Triangles(tris) => {
                let root = dsu.find(l[0]);
                let r = reference[&root];
                let fill_volume: f64 =
                    tris.iter().map(|t| tet(r, p[t[0] as usize], p[t[1] as usize], p[t[2] as usize])).sum();
                let enclosed = (volume[&root] - fan + fill_volume).abs();
                let area: f64 = tris.iter().map(|t| triangle_area(p, t)).sum();
                if !(enclosed >= opts.min_depth * area.powf(1.5)) {
                    report.open_shallow += 1;
                    continue;
                }
                candidates.push((tris, area));
            }
        }
    }
    // The lids' probe points: the centroids of each lid's largest triangles.
    let probes: Vec<Vec<[f64; 3]>> = candidates
        .iter()
        .map(|(tris, _)| {
            let mut by_area: Vec<&[u32; 3]> = tris.iter().collect();
            by_area.sort_by(|a, b| triangle_area(p, b).total_cmp(&triangle_area(p, a)));
            let m = (LID_PROBES_BUDGET / welded.len().max(1)).clamp(1, LID_PROBES);
            by_area.iter().take(m).map(|t| centroid(p, &t[..])).collect()
        })
        .collect();
    let flat: Vec<[f64; 3]> = probes.iter().flatten().copied().collect();
    let w = winding_numbers(p, &welded, &flat);
    let mut at = 0;
    for ((tris, area), probe) in candidates.into_iter().zip(&probes) {
        let mean = w[at..at + probe.len()].iter().map(|w| w.abs()).sum::<f64>() / probe.len() as f64;
        at += probe.len();
        if !(LID_WINDING.0..=LID_WINDING.1).contains(&mean) {
            report.open_not_on_boundary += 1;
            continue;
        }
        report.loops_filled += 1;
        report.filled_area += area;
        report.triangles_added += tris.len();
        out.triangles.extend(tris);
    }
    (out, report)
}

/// The open mesh's |winding number| at a lid's points must lie in this range (mean over
/// up to [`LID_PROBES`] points) for the lid to be made. On the plane of a lid the lid itself
/// adds nothing, so there the open mesh's winding number is the mean of the filled mesh's
/// on the lid's two sides: ½ where the lid is the boundary of the solid it closes (a single
/// planar hole in an otherwise closed surface: exactly ½; an open pipe's ends, each pulled
/// by the other's hole: 0.45), near 1 or 0 where it would lie inside the solid or outside
/// it (a tube's open top just under the lid of a wider hole around it: libigl's halftunnel,
/// whose post's top, filled, gave the crust a sliver and genus 19 instead of 1).
pub const LID_WINDING: (f64, f64) = (0.3, 0.7);

/// Points of a lid at which [`LID_WINDING`] is checked.
pub const LID_PROBES: usize = 8;

/// Bound on triangles × points of the lids' winding numbers (by direct summation): a mesh
/// of more than this over [`LID_PROBES`] triangles checks fewer points per lid, one at least.
pub const LID_PROBES_BUDGET: usize = 1 << 26;

/// The generalized winding number of `triangles` at each of `points`, by direct summation
/// of the triangles' signed solid angles (Van Oosterom and Strackee).
fn winding_numbers(p: &[[f64; 3]], triangles: &[[u32; 3]], points: &[[f64; 3]]) -> Vec<f64> {
    points
        .iter()
        .map(|q| {
            let mut total = 0.0;
            for t in triangles {
                let [a, b, c] = t.map(|v| {
                    let x = p[v as usize];
                    [x[0] - q[0], x[1] - q[1], x[2] - q[2]]
                });
                let (la, lb, lc) = (norm(a), norm(b), norm(c));
                let det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                    + a[2] * (b[0] * c[1] - b[1] * c[0]);
                let dot = |u: [f64; 3], v: [f64; 3]| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
                let den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
                total += 2.0 * det.atan2(den);
            }
            total / (4.0 * std::f64::consts::PI)
        })
        .collect()
}

/// Each vertex's representative: the first vertex at the same position (−0 and +0 equal,
/// as [`crate::weld::weld_exact`] welds, but keeping the input's indices).
fn weld_by_position(positions: &[[f64; 3]]) -> Vec<u32> {
    let mut first: HashMap<[u64; 3], u32> = HashMap::with_capacity(positions.len());
    positions
        .iter()
        .enumerate()
        .map(|(i, q)| *first.entry(q.map(|x| (x + 0.0).to_bits())).or_insert(i as u32))
        .collect()
}

/// The boundary loops of welded, non-degenerate triangles, each a simple cycle of vertices
/// in the direction of its boundary half-edges (the triangles' own), and the first vertex
/// of each boundary edge on no loop. Deterministic: loops are traced from the smallest unused
/// half-edge, and at a vertex with several ways on the smallest is taken.
fn boundary_loops(triangles: &[[u32; 3]]) -> (Vec<Vec<u32>>, Vec<u32>) {
    // Undirected edge → (uses, the half-edge of its first use).
    let mut edges: HashMap<(u32, u32), (u32, (u32, u32))> = HashMap::with_capacity(3 * triangles.len() / 2);
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edges.entry((a.min(b), a.max(b))).or_insert((0, (a, b))).0 += 1;
        }
    }
    let mut half: Vec<(u32, u32)> = edges.values().filter(|(n, _)| *n == 1).map(|(_, h)| *h).collect();
    half.sort_unstable();
    // Outgoing boundary half-edges of each vertex: a range of `half`, which is sorted.
    let mut out: HashMap<u32, (usize, usize)> = HashMap::new();
    for (i, &(a, _)) in half.iter().enumerate() {
        out.entry(a).and_modify(|r| r.1 = i + 1).or_insert((i, i + 1));
    }
    let mut used = vec![false; half.len()];
    let next_unused = |v: u32, used: &[bool]| -> Option<usize> {
        let &(lo, hi) = out.get(&v)?;
        (lo..hi).find(|&i| !used[i])
    };
    let (mut loops, mut untraced) = (Vec::new(), Vec::new());
    for start in 0..half.len() {
        if used[start] {
            continue;
        }
        // The walk so far (vertices, the last one's position in it) and its edges.
        let mut path = vec![half[start].0];
        let mut at: HashMap<u32, usize> = HashMap::from([(half[start].0, 0)]);
        let mut path_edges = 0usize;
        let mut e = start;
        loop {
            used[e] = true;
            path_edges += 1;
            let v = half[e].1;
            if let Some(&i) = at.get(&v) {
                // Closed a cycle at v: split it off and go on from v.
                let cycle = path.split_off(i + 1);
                let mut l = vec![v];
                l.extend_from_slice(&cycle);
                for u in &cycle {
                    at.remove(u);
                }
                path_edges -= l.len();
                loops.push(l);
                if path_edges == 0 {
                    break;
                }
            } else {
                at.insert(v, path.len());
                path.push(v);
            }
            match next_unused(v, &used) {
                Some(n) => e = n,
                None => {
                    untraced.extend_from_slice(&path[path.len() - path_edges..]);
                    break;
                }
            }
        }
    }
    (loops, untraced)
}

/// What one loop's fill is.
enum Fill {
    Degenerate,
    NotPlanar,
    NotSimple,
    /// The fill's triangles, each rim edge run against the loop's direction.
    Triangles(Vec<[u32; 3]>),
}

/// The flat fill of one loop (vertex indices into `p`, in the boundary half-edges'
/// direction), or why there is none.
#[allow(clippy::neg_cmp_op_on_partial_ord, reason = "a NaN must fail these tests, and !(x > 0.0) holds for it")]
fn fill_loop(p: &[[f64; 3]], l: &[u32], planarity: f64) -> Fill {
    let n = l.len();
    if n < 3 {
        return Fill::Degenerate;
    }
    let c = centroid(p, l);
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut cov = [[0.0; 3]; 3];
    for &v in l {
        let q = p[v as usize];
        let d = [0, 1, 2].map(|k| q[k] - c[k]);
        for i in 0..3 {
            lo[i] = lo[i].min(q[i]);
            hi[i] = hi[i].max(q[i]);
            for j in 0..3 {
                cov[i][j] += d[i] * d[j];
            }
        }
    }
    let extent = norm([0, 1, 2].map(|k| hi[k] - lo[k]));
    if !(extent > 0.0 && extent.is_finite()) {
        return Fill::Degenerate;
    }
    let (normal, u, v) = principal_frame(cov);
    let off = |q: [f64; 3], axis: [f64; 3]| (0..3).map(|k| (q[k] - c[k]) * axis[k]).sum::<f64>();
    if l.iter().any(|&i| !(off(p[i as usize], normal).abs() <= planarity * extent)) {
        return Fill::NotPlanar;
    }
    let flat: Vec<[f64; 2]> = l.iter().map(|&i| [off(p[i as usize], u), off(p[i as usize], v)]).collect();
    let twice_area: f64 = (0..n)
        .map(|i| {
            let (a, b) = (flat[i], flat[(i + 1) % n]);
            a[0] * b[1] - a[1] * b[0]
        })
        .sum();
    // Below this the polygon has no area to speak of (a slit, a loop folded onto itself).
    if !(twice_area.abs() > 1e-12 * extent * extent) {
        return Fill::Degenerate;
    }
    match triangulate(&flat, twice_area > 0.0) {
        // Spade's faces run counter-clockwise in the plane; the fill must run each rim
        // edge against the loop, so against a counter-clockwise loop they are turned.
        Some(faces) => Fill::Triangles(
            faces
                .into_iter()
                .map(|f| {
                    let t = f.map(|k| l[k]);
                    if twice_area > 0.0 {
                        [t[0], t[2], t[1]]
                    } else {
                        t
                    }
                })
                .collect(),
        ),
        None => Fill::NotSimple,
    }
}

/// The triangles (counter-clockwise, as indices into `polygon`) of the constrained Delaunay
/// triangulation of a simple polygon that lie inside it, or `None` when the polygon is not
/// simple (two vertices at one point, edges crossing, or an edge through another vertex).
/// `ccw`: the polygon's orientation.
fn triangulate(polygon: &[[f64; 2]], ccw: bool) -> Option<Vec<[usize; 3]>> {
    let n = polygon.len();
    let mut cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::new();
    let mut handles = Vec::with_capacity(n);
    for (i, q) in polygon.iter().enumerate() {
        let h = cdt.insert(Point2::new(q[0], q[1])).ok()?;
        // An existing vertex comes back for a point already inserted.
        if h.index() != i {
            return None;
        }
        handles.push(h);
    }
    let mut seeds = Vec::with_capacity(n);
    for i in 0..n {
        let before = cdt.num_constraints();
        let added = cdt.try_add_constraint(handles[i], handles[(i + 1) % n]);
        if added.len() != 1 || cdt.num_constraints() != before + 1 {
            return None;
        }
        let e = cdt.directed_edge(added[0]);
        // The polygon's inside is on the left of its edges when it runs counter-clockwise.
        let face = if ccw { e.face() } else { e.rev().face() };
        seeds.push(face.as_inner()?.fix());
    }
    let mut inside = vec![false; cdt.num_all_faces()];
    let mut queue: VecDeque<_> = seeds.into_iter().collect();
    let mut faces = Vec::new();
    while let Some(f) = queue.pop_front() {
        if std::mem::replace(&mut inside[f.index()], true) {
            continue;
        }
        let face = cdt.face(f);
        faces.push(face.vertices().map(|v| v.fix().index()));
        for e in face.adjacent_edges() {
            if !e.is_constraint_edge() {
                let g = e.rev().face().as_inner()?.fix();
                if !inside[g.index()] {
                    queue.push_back(g);
                }
            }
        }
    }
    Some(faces)
}

/// Unit normal of the plane fitted to points with scatter matrix `cov` (the eigenvector of
/// its smallest eigenvalue), and two unit vectors spanning the plane, by cyclic Jacobi
/// rotations (3×3, converges in a handful of sweeps).
#[allow(clippy::neg_cmp_op_on_partial_ord, reason = "a NaN must fail these tests, and !(x > 0.0) holds for it")]
fn principal_frame(mut a: [[f64; 3]; 3]) -> ([f64; 3], [f64; 3], [f64; 3]) {
    let mut vecs = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _ in 0..50 {
        let off = a[0][1].powi(2) + a[0][2].powi(2) + a[1][2].powi(2);
        let scale = a[0][0].powi(2) + a[1][1].powi(2) + a[2][2].powi(2);
        if !(off > 1e-30 * scale) {
            break;
        }
        for (pi, qi) in [(0, 1), (0, 2), (1, 2)] {
            if a[pi][qi] == 0.0 {
                continue;
            }
            let theta = (a[qi][qi] - a[pi][pi]) / (2.0 * a[pi][qi]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let cs = 1.0 / (t * t + 1.0).sqrt();
            let sn = t * cs;
            // A ← Jᵀ A J on rows and columns p, q; V ← V J.
            for row in &mut a {
                let (akp, akq) = (row[pi], row[qi]);
                row[pi] = cs * akp - sn * akq;
                row[qi] = sn * akp + cs * akq;
            }
            let (rp, rq) = (a[pi], a[qi]);
            a[pi] = [0, 1, 2].map(|k| cs * rp[k] - sn * rq[k]);
            a[qi] = [0, 1, 2].map(|k| sn * rp[k] + cs * rq[k]);
            for row in &mut vecs {
                let (vp, vq) = (row[pi], row[qi]);
                row[pi] = cs * vp - sn * vq;
                row[qi] = sn * vp + cs * vq;
            }
        }
    }
    // Column j of `vecs` is the eigenvector of a[j][j].
    let mut order = [0, 1, 2];
    order.sort_by(|&i, &j| a[i][i].total_cmp(&a[j][j]));
    let column = |j: usize| {
        let c = [vecs[0][j], vecs[1][j], vecs[2][j]];
        let l = norm(c);
        c.map(|x| x / l)
    };
    let (n, u) = (column(order[0]), column(order[2]));
    let v = [n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2], n[0] * u[1] - n[1] * u[0]];
    (n, u, v)
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn centroid(p: &[[f64; 3]], l: &[u32]) -> [f64; 3] {
    let mut c = [0.0; 3];
    for &v in l {
        for k in 0..3 {
            c[k] += p[v as usize][k];
        }
    }
    c.map(|x| x / l.len() as f64)
}

/// Signed volume of the tetrahedron (r, a, b, c).
fn tet(r: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let (a, b, c) = ([0, 1, 2].map(|k| a[k] - r[k]), [0, 1, 2].map(|k| b[k] - r[k]), [0, 1, 2].map(|k| c[k] - r[k]));
    (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])) / 6.0
}

/// Signed volume, seen from `r`, of the fan from a loop's centroid that closes it (each rim
/// edge run against the loop, as a fill runs it).
fn fan_volume(p: &[[f64; 3]], l: &[u32], r: [f64; 3]) -> f64 {
    let m = centroid(p, l);
    (0..l.len()).map(|i| tet(r, m, p[l[(i + 1) % l.len()] as usize], p[l[i] as usize])).sum()
}

fn triangle_area(p: &[[f64; 3]], t: &[u32; 3]) -> f64 {
    let [a, b, c] = t.map(|v| p[v as usize]);
    let (u, w) = ([0, 1, 2].map(|k| b[k] - a[k]), [0, 1, 2].map(|k| c[k] - a[k]));
    0.5 * norm([u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes::cuboid;
    use crate::TopologyReport;

    /// Triangles and shared vertices from quads given by corner positions.
    fn from_quads(quads: &[[[f64; 3]; 4]]) -> TriMesh {
        let mut index: HashMap<[u64; 3], u32> = HashMap::new();
        let mut positions = Vec::new();
        let mut id = |q: [f64; 3]| {
            *index.entry(q.map(f64::to_bits)).or_insert_with(|| {
                positions.push(q);
                positions.len() as u32 - 1
            })
        };
        let mut triangles = Vec::new();
        for q in quads {
            let v = q.map(&mut id);
            triangles.push([v[0], v[1], v[2]]);
            triangles.push([v[0], v[2], v[3]]);
        }
        TriMesh { positions, triangles }
    }

    /// The unit cube's surface, each face an n × n grid of quads (counter-clockwise seen
    /// from outside), without the cells of the top face (z = 1) that `hole` names.
    fn grid_box(n: usize, hole: impl Fn(usize, usize) -> bool) -> TriMesh {
        let s = 1.0 / n as f64;
        let mut quads = Vec::new();
        // Face frames: a corner, two in-face axes whose cross product points outwards.
        let faces: [([f64; 3], [f64; 3], [f64; 3]); 6] = [
            ([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]),
            ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
            ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
            ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]),
            ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
        ];
        for (f, (o, a, b)) in faces.iter().enumerate() {
            for i in 0..n {
                for j in 0..n {
                    if f == 1 && hole(i, j) {
                        continue;
                    }
                    let at = |di: usize, dj: usize| {
                        [0, 1, 2].map(|k| o[k] + s * ((i + di) as f64 * a[k] + (j + dj) as f64 * b[k]))
                    };
                    quads.push([at(0, 0), at(1, 0), at(1, 1), at(0, 1)]);
                }
            }
        }
        from_quads(&quads)
    }

    fn closed_and_oriented(m: &TriMesh) -> TopologyReport {
        let t = TopologyReport::of(m);
        assert!(t.is_closed && t.is_orientation_consistent && t.is_manifold, "{t:?}");
        t
    }

    #[test]
    fn the_bottomless_cube_gets_its_bottom() {
        let cube = cuboid([0.0; 3], [1.0; 3]);
        let open = TriMesh { positions: cube.positions.clone(), triangles: cube.triangles[2..].to_vec() };
        assert!(!TopologyReport::of(&open).is_closed);
        let (filled, r) = fill_planar_holes(&open, &FillOptions::default());
        assert_eq!((r.loops_found, r.loops_filled, r.triangles_added), (1, 1, 2), "{r:?}");
        assert!((r.filled_area - 1.0).abs() < 1e-12, "{r:?}");
        assert_eq!(filled.triangles[..10], open.triangles[..]);
        assert_eq!(filled.positions, open.positions);
        let t = closed_and_oriented(&filled);
        assert!((t.signed_volume - 1.0).abs() < 1e-12, "{t:?}");
        // Turned inside out (a cavity's wall), it is closed inside out.
        let inward = TriMesh {
            positions: open.positions.clone(),
            triangles: open.triangles.iter().map(|t| [t[0], t[2], t[1]]).collect(),
        };
        let (filled, r) = fill_planar_holes(&inward, &FillOptions::default());
        assert_eq!(r.loops_filled, 1);
        assert!((closed_and_oriented(&filled).signed_volume + 1.0).abs() < 1e-12);
        // A closed mesh has nothing to fill.
        let (same, r) = fill_planar_holes(&cube, &FillOptions::default());
        assert_eq!((same, r), (cube, HoleFilling::default()));
    }

    #[test]
    fn a_bottomless_cube_with_unwelded_faces_is_closed_across_the_seams() {
        // Each face on vertices of its own: the rim is found by position and the fill uses
        // the first vertex at each position.
        let cube = cuboid([0.0; 3], [1.0; 3]);
        let mut m = TriMesh::default();
        for pair in cube.triangles[2..].chunks(2) {
            let n = m.positions.len() as u32;
            let mut local: Vec<u32> = Vec::new();
            for t in pair {
                m.triangles.push(t.map(|v| {
                    let i = local.iter().position(|&w| w == v).unwrap_or_else(|| {
                        local.push(v);
                        local.len() - 1
                    });
                    n + i as u32
                }));
            }
            m.positions.extend(local.iter().map(|&v| cube.positions[v as usize]));
        }
        let (filled, r) = fill_planar_holes(&m, &FillOptions::default());
        assert_eq!((r.loops_found, r.loops_filled), (1, 1), "{r:?}");
        closed_and_oriented(&crate::weld::weld_exact(&filled));
    }

    #[test]
    fn a_non_convex_hole_is_filled_exactly() {
        // A 4 × 4 top face without an L of three cells (area 3/16).
        let open = grid_box(4, |i, j| matches!((i, j), (1, 1) | (2, 1) | (1, 2)));
        let (filled, r) = fill_planar_holes(&open, &FillOptions::default());
        assert_eq!((r.loops_found, r.loops_filled), (1, 1), "{r:?}");
        assert!((r.filled_area - 3.0 / 16.0).abs() < 1e-12, "{r:?}");
        // Eight rim vertices, no new one: six triangles.
        assert_eq!(r.triangles_added, 6);
        let t = closed_and_oriented(&filled);
        assert!((t.signed_volume - 1.0).abs() < 1e-12 && (t.surface_area - 6.0).abs() < 1e-12, "{t:?}");
    }

    #[test]
    fn two_holes_touching_at_a_vertex_are_both_filled() {
        // Cells (1, 1) and (2, 2) share the vertex (2, 2): a pinch of the rim.
        let open = grid_box(4, |i, j| matches!((i, j), (1, 1) | (2, 2)));
        let (filled, r) = fill_planar_holes(&open, &FillOptions::default());
        assert_eq!((r.loops_found, r.loops_filled, r.untraced_boundary_edges), (2, 2, 0), "{r:?}");
        assert!((r.filled_area - 2.0 / 16.0).abs() < 1e-12, "{r:?}");
        let t = TopologyReport::of(&filled);
        assert!(t.is_closed && t.is_orientation_consistent, "{t:?}");
        assert!((t.signed_volume - 1.0).abs() < 1e-12);
    }

    #[test]
    fn an_open_tube_gets_both_ends() {
        let cube = cuboid([0.0; 3], [1.0; 3]);
        // Without the bottom (z = 0) and top (z = 1) faces: two planar loops, whose fills
        // each close the tube with the other end fanned.
        let tube = TriMesh { positions: cube.positions.clone(), triangles: cube.triangles[4..].to_vec() };
        let (filled, r) = fill_planar_holes(&tube, &FillOptions::default());
        assert_eq!((r.loops_found, r.loops_filled), (2, 2), "{r:?}");
        assert!((closed_and_oriented(&filled).signed_volume - 1.0).abs() < 1e-12);
    }

    /// A half sphere of radius 1 (z ≥ 0, `rings` latitude rings) on a UV grid, whose rim is
    /// the equator, or with its rim lifted to z = 0.3·cos 2φ (a saddle) when `saddle`.
    fn bowl(rings: usize, sectors: usize, saddle: bool) -> TriMesh {
        let at = |i: usize, j: usize| {
            let theta = std::f64::consts::FRAC_PI_2 * i as f64 / rings as f64;
            let phi = std::f64::consts::TAU * (j % sectors) as f64 / sectors as f64;
            let lift = if saddle { 0.3 * (2.0 * phi).cos() * (i as f64 / rings as f64) } else { 0.0 };
            [theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos() + lift]
        };
        let mut positions = vec![at(0, 0)];
        for i in 1..=rings {
            for j in 0..sectors {
                positions.push(at(i, j));
            }
        }
        let id = |i: usize, j: usize| if i == 0 { 0 } else { (1 + (i - 1) * sectors + j % sectors) as u32 };
        let mut triangles = Vec::new();
        for j in 0..sectors {
            triangles.push([0, id(1, j), id(1, j + 1)]);
            for i in 1..rings {
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        TriMesh { positions, triangles }
    }

    #[test]
    fn a_hemisphere_is_closed_by_its_disc_and_a_saddle_rim_is_left_open() {
        let (filled, r) = fill_planar_holes(&bowl(8, 32, false), &FillOptions::default());
        assert_eq!((r.loops_found, r.loops_filled, r.triangles_added), (1, 1, 30), "{r:?}");
        let disc = 0.5 * 32.0 * (std::f64::consts::TAU / 32.0).sin();
        assert!((r.filled_area - disc).abs() < 1e-9, "{r:?} against {disc}");
        closed_and_oriented(&filled);
        let saddle = bowl(8, 32, true);
        let (same, r) = fill_planar_holes(&saddle, &FillOptions::default());
        assert_eq!((r.loops_found, r.loops_filled, r.open_not_planar), (1, 0, 1), "{r:?}");
        assert_eq!(same, saddle);
    }

    #[test]
    fn sheets_and_soups_are_not_doubled() {
        // A flat square patch: its outline is planar and simple, but closes no volume.
        let patch = from_quads(&[[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]]);
        let (same, r) = fill_planar_holes(&patch, &FillOptions::default());
        assert_eq!((r.loops_found, r.loops_filled, r.open_shallow), (1, 0, 1), "{r:?}");
        assert_eq!(same, patch);
        // ... unless asked for.
        let (_, r) = fill_planar_holes(&patch, &FillOptions { min_depth: 0.0, ..Default::default() });
        assert_eq!(r.loops_filled, 1);
        // A level-rimmed terrain with a low bump (mean height 2% of its width).
        let n = 16;
        let h = |i: usize, j: usize| {
            let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
            0.08 * (std::f64::consts::PI * x).sin().powi(2) * (std::f64::consts::PI * y).sin().powi(2)
        };
        let mut quads = Vec::new();
        for i in 0..n {
            for j in 0..n {
                let at = |a: usize, b: usize| [a as f64 / n as f64, b as f64 / n as f64, h(a, b)];
                quads.push([at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        let terrain = from_quads(&quads);
        let (_, r) = fill_planar_holes(&terrain, &FillOptions::default());
        assert_eq!((r.loops_found, r.loops_filled, r.open_shallow), (1, 0, 1), "{r:?}");
        // A soup: every triangle its own loop, each planar and simple.
        let cube = cuboid([0.0; 3], [1.0; 3]);
        let soup = TriMesh {
            positions: cube.triangles.iter().flat_map(|t| t.map(|v| cube.positions[v as usize])).collect::<Vec<_>>(),
            triangles: (0..12).map(|f| [3 * f, 3 * f + 1, 3 * f + 2]).collect(),
        };
        // (The soup's corners coincide, so shrink each triangle a little about its centroid.)
        let soup = TriMesh {
            positions: soup
                .positions
                .chunks(3)
                .flat_map(|t| {
                    let c = [0, 1, 2].map(|k| (t[0][k] + t[1][k] + t[2][k]) / 3.0);
                    t.iter().map(move |p| [0, 1, 2].map(|k| c[k] + 0.9 * (p[k] - c[k]))).collect::<Vec<_>>()
                })
                .collect(),
            ..soup
        };
        let (same, r) = fill_planar_holes(&soup, &FillOptions::default());
        assert_eq!((r.loops_found, r.loops_filled, r.open_shallow), (12, 0, 12), "{r:?}");
        assert_eq!(same, soup);
    }

    /// A half cylinder of radius 1 and length 2 along z (the arch y ≥ 0), open at both
    /// ends, and with `floor` its floor (y = 0) too.
    fn half_tunnel(floor: bool) -> TriMesh {
        let (na, nz) = (16, 4);
        let at = |i: usize, k: usize| {
            let a = std::f64::consts::PI * i as f64 / na as f64;
            [a.cos(), a.sin(), 2.0 * k as f64 / nz as f64]
        };
        let mut quads = Vec::new();
        for k in 0..nz {
            for i in 0..na {
                quads.push([at(i, k), at(i, k + 1), at(i + 1, k + 1), at(i + 1, k)]);
            }
            if floor {
                // From x = −1 to 1 under the arch, facing into the tunnel as the arch does.
                quads.push([at(na, k), at(na, k + 1), at(0, k + 1), at(0, k)]);
            }
        }
        from_quads(&quads)
    }

    #[test]
    fn a_half_tunnel_is_closed_at_its_ends_only_when_it_has_a_floor() {
        // The arch alone has one loop (arc, floor edge, arc, floor edge): not planar.
        let arch = half_tunnel(false);
        let (same, r) = fill_planar_holes(&arch, &FillOptions::default());
        assert_eq!((r.loops_found, r.loops_filled, r.open_not_planar), (1, 0, 1), "{r:?}");
        assert_eq!(same, arch);
        // With its floor, each end is a half disc: both closed, a closed half cylinder.
        let (filled, r) = fill_planar_holes(&half_tunnel(true), &FillOptions::default());
        assert_eq!((r.loops_found, r.loops_filled), (2, 2), "{r:?}");
        let half_disc = 0.5 * 16.0 * (std::f64::consts::PI / 16.0).sin();
        assert!((r.filled_area - 2.0 * half_disc).abs() < 1e-9, "{r:?}");
        let t = closed_and_oriented(&filled);
        assert!((t.signed_volume + 2.0 * half_disc).abs() < 1e-9, "inside out, as given: {t:?}");
    }

    #[test]
    fn a_lid_inside_the_solid_is_not_made() {
        // A cube without its bottom inside a closed box: its lid would lie inside the box's
        // solid (the open mesh's winding number there is 1.5), an interior face.
        let outer = cuboid([-1.0; 3], [2.0; 3]);
        let inner = cuboid([0.0; 3], [1.0; 3]);
        let n = outer.positions.len() as u32;
        let m = TriMesh {
            positions: outer.positions.iter().chain(&inner.positions).copied().collect(),
            triangles: outer
                .triangles
                .iter()
                .copied()
                .chain(inner.triangles[2..].iter().map(|t| t.map(|v| v + n)))
                .collect(),
        };
        let (same, r) = fill_planar_holes(&m, &FillOptions::default());
        assert_eq!((r.loops_found, r.loops_filled, r.open_not_on_boundary), (1, 0, 1), "{r:?}");
        assert_eq!(same, m);
    }

    #[test]
    fn crossing_or_touching_polygons_are_not_triangulated() {
        let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        assert_eq!(triangulate(&square, true).map(|f| f.len()), Some(2));
        let mut cw = square;
        cw.reverse();
        assert_eq!(triangulate(&cw, false).map(|f| f.len()), Some(2));
        let bowtie = [[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]];
        assert_eq!(triangulate(&bowtie, true), None);
        // A vertex on another edge, and a vertex twice.
        assert_eq!(triangulate(&[[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 0.0], [0.0, 1.0]], true), None);
        assert_eq!(triangulate(&[[0.0, 0.0], [1.0, 0.0], [0.0, 0.0], [0.0, 1.0]], true), None);
    }

    #[test]
    fn open_rims_that_do_not_chain_are_skipped() {
        // Two triangles sharing an edge, run the same way (inconsistent): the boundary
        // half-edges do not chain into a loop. Nothing panics, nothing is filled.
        let m = TriMesh {
            positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 1.0]],
            triangles: vec![[0, 1, 2], [1, 2, 3]],
        };
        let (same, r) = fill_planar_holes(&m, &FillOptions::default());
        assert_eq!(same, m);
        assert_eq!(r.loops_filled, 0);
        assert!(r.untraced_boundary_edges > 0, "{r:?}");
    }
}
