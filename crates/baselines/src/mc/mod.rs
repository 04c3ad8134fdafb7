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
//! only at ≤ 6 heights (see `connected_in_cube`). [`Ambiguity::SeparateAbove`] and
//! [`Ambiguity::JoinAbove`] are fixed face rules without interior test (the classic 256-case
//! table is `SeparateAbove`).
//!
//! # Triangulation
//!
//! Where a cell's polygons are those of the classic 256-case table (every face separating
//! its above corners and no tube: always with `SeparateAbove`, and in every unambiguous cell
//! and most ambiguous ones with the default), the cell's triangles are the table's (see
//! `classic_triangles`; the polygons of all 256 cases are checked against the table in this
//! module's tests). Elsewhere each polygon is a fan from a corner whose diagonals all leave
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

use std::collections::HashMap;

use mesh_io::TriMesh;
use ndarray::ArrayView3;

use crate::error::{config_err, BaselineError, Result};
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
    pub level: f64,
    /// Position of grid point `[0, 0, 0]`.
    pub origin: [f64; 3],
    /// Distance between grid points along each axis (> 0).
    pub spacing: [f64; 3],
    pub inside: Inside,
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

/// Cube corners: bit 0 → +axis 0, bit 1 → +axis 1, bit 2 → +axis 2. Faces as corner
/// cycles counter-clockwise seen from outside the cube.
const FACES: [[usize; 4]; 6] = [[0, 4, 6, 2], [1, 3, 7, 5], [0, 1, 5, 4], [2, 6, 7, 3], [0, 2, 3, 1], [4, 5, 7, 6]];

/// Local edge index of the cube edge between corners `a` and `b` (adjacent): the axis
/// (bit that differs) times 4 plus the other two bits of the lower corner.
const fn edge_of(a: usize, b: usize) -> usize {
    let lo = if a < b { a } else { b };
    let axis = (a ^ b).trailing_zeros() as usize;
    let rest = match axis {
        0 => lo >> 1,
        1 => (lo & 1) | ((lo >> 2) << 1),
        _ => lo & 3,
    };
    axis * 4 + rest
}

/// Lower corner of local edge `e`.
const fn edge_lower_corner(e: usize) -> usize {
    let (axis, rest) = (e / 4, e % 4);
    match axis {
        0 => rest << 1,
        1 => (rest & 1) | ((rest >> 1) << 2),
        _ => rest,
    }
}

/// Bit `f` set when local edge `e` lies on face `f` of [`FACES`].
const fn edge_face_mask(e: usize) -> u8 {
    let mut m = 0u8;
    let mut f = 0;
    while f < 6 {
        let mut q = 0;
        while q < 4 {
            if edge_of(FACES[f][q], FACES[f][(q + 1) % 4]) == e {
                m |= 1 << f;
            }
            q += 1;
        }
        f += 1;
    }
    m
}

/// Bit `f` set when corner `c` lies on face `f`.
const fn corner_face_mask(c: usize) -> u8 {
    let mut m = 0u8;
    let mut f = 0;
    while f < 6 {
        let mut q = 0;
        while q < 4 {
            if FACES[f][q] == c {
                m |= 1 << f;
            }
            q += 1;
        }
        f += 1;
    }
    m
}

/// The level set of `grid` as a welded triangle mesh (see the module documentation).
///
/// Errors: a grid smaller than 2 along an axis, a non-finite value, level, origin or
/// spacing, or a non-positive spacing. An empty mesh (no crossing) is not an error.
pub fn marching_cubes(grid: ArrayView3<f64>, opts: &McOptions) -> Result<TriMesh> {
    let (nx, ny, nz) = grid.dim();
    if nx < 2 || ny < 2 || nz < 2 {
        return config_err("grid", format!("{nx}×{ny}×{nz}"), "marching cubes needs at least 2 points per axis");
    }
    if nx.checked_mul(ny).and_then(|v| v.checked_mul(nz)).is_none_or(|n| n >= (1usize << 40)) {
        return config_err("grid", format!("{nx}×{ny}×{nz}"), "too many grid points");
    }
    if !opts.level.is_finite() {
        return config_err("level", opts.level, "must be finite");
    }
    for k in 0..3 {
        if !opts.origin[k].is_finite() {
            return config_err("origin", format!("{:?}", opts.origin), "must be finite");
        }
        if !(opts.spacing[k].is_finite() && opts.spacing[k] > 0.0) {
            return config_err("spacing", format!("{:?}", opts.spacing), "must be finite and positive");
        }
    }
    if let Some((idx, v)) = grid.indexed_iter().find(|(_, v)| !v.is_finite()) {
        return Err(BaselineError::Data(format!("grid value at {idx:?} is {v}")));
    }

    let level = opts.level;
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut vertex_of: HashMap<u64, u32> = HashMap::new();
    let (sx, sy) = ((ny * nz) as u64, nz as u64);
    let point_key = |i: usize, j: usize, k: usize| i as u64 * sx + j as u64 * sy + k as u64;
    let n_points = (nx * ny * nz) as u64;

    let mut v = [0.0f64; 8];
    let mut local_vertex = [u32::MAX; 12];
    let mut local_faces = [0u8; 12];
    let edge_faces: [u8; 12] = std::array::from_fn(edge_face_mask);
    let mut cycles: [Vec<(u32, u8)>; 6] = std::array::from_fn(|_| Vec::with_capacity(12));
    let mut fan: Vec<[u32; 3]> = Vec::with_capacity(48);
    let mut tri_buf: Vec<[u32; 3]> = Vec::with_capacity(16);
    for i in 0..nx - 1 {
        for j in 0..ny - 1 {
            for k in 0..nz - 1 {
                let mut mask = 0u32;
                for (c, vc) in v.iter_mut().enumerate() {
                    *vc = grid[[i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2)]] - level;
                    if *vc > 0.0 {
                        mask |= 1 << c;
                    }
                }
                if mask == 0 || mask == 255 {
                    continue;
                }
                let (succ, joined_faces, ambiguous_faces) = face_segments(&v, mask, opts.ambiguity);
                // Vertices of the crossed edges.
                for e in 0..12 {
                    local_vertex[e] = u32::MAX;
                    if succ[e] == usize::MAX {
                        continue;
                    }
                    let lo = edge_lower_corner(e);
                    let hi = lo | (1 << (e / 4));
                    let (vl, vh) = (v[lo], v[hi]);
                    let gl = [i + (lo & 1), j + ((lo >> 1) & 1), k + (lo >> 2)];
                    let axis = e / 4;
                    // Exactly on the level: the vertex is the grid point, shared by its edges.
                    local_faces[e] = edge_faces[e];
                    let (key, pos) = if vl == 0.0 || vh == 0.0 {
                        let (g, c) = if vl == 0.0 {
                            (gl, lo)
                        } else {
                            (
                                [
                                    gl[0] + (axis == 0) as usize,
                                    gl[1] + (axis == 1) as usize,
                                    gl[2] + (axis == 2) as usize,
                                ],
                                hi,
                            )
                        };
                        local_faces[e] = corner_face_mask(c);
                        (3 * n_points + point_key(g[0], g[1], g[2]), g.map(|c| c as f64))
                    } else {
                        let wl = 1.0 / (f64::EPSILON + vl.abs());
                        let wh = 1.0 / (f64::EPSILON + vh.abs());
                        let mut p = gl.map(|c| c as f64);
                        p[axis] += wh / (wl + wh);
                        (axis as u64 * n_points + point_key(gl[0], gl[1], gl[2]), p)
                    };
                    local_vertex[e] = *vertex_of.entry(key).or_insert_with(|| {
                        positions.push([
                            opts.origin[0] + opts.spacing[0] * pos[0],
                            opts.origin[1] + opts.spacing[1] * pos[1],
                            opts.origin[2] + opts.spacing[2] * pos[2],
                        ]);
                        (positions.len() - 1) as u32
                    });
                }
                // Chain the segments into cycles.
                let mut n_cycles = 0;
                let mut seen = 0u32;
                for start in 0..12 {
                    if succ[start] == usize::MAX || seen & (1 << start) != 0 {
                        continue;
                    }
                    let cycle = &mut cycles[n_cycles];
                    n_cycles += 1;
                    cycle.clear();
                    let mut e = start;
                    while e < 12 && seen & (1 << e) == 0 {
                        seen |= 1 << e;
                        let vid = local_vertex[e];
                        if cycle.last().map(|c| c.0) != Some(vid) {
                            cycle.push((vid, local_faces[e]));
                        }
                        e = succ[e];
                    }
                    if cycle.len() > 1 && cycle.first().map(|c| c.0) == cycle.last().map(|c| c.0) {
                        cycle.pop();
                    }
                }
                // Two polygons around two same-sign regions that the trilinear interpolant
                // joins through the cell: one tube instead of two discs.
                let tube = opts.ambiguity == Ambiguity::AsymptoticDecider
                    && n_cycles == 2
                    && cycles[0].len() >= 3
                    && cycles[1].len() >= 3
                    && joined_inside(&v, mask, joined_faces, ambiguous_faces);
                fan.clear();
                // Where the cell's polygons are the classic table's (every face separating its
                // above corners, no tube), its triangulation is the classic table's too.
                let classic = match opts.ambiguity {
                    Ambiguity::SeparateAbove => true,
                    Ambiguity::AsymptoticDecider => joined_faces == 0 && !tube,
                    Ambiguity::JoinAbove => false,
                };
                if classic && classic_triangles(mask, &local_vertex, &mut fan) {
                    // The table's triangles are in `fan`.
                } else if tube {
                    let (c1, c2) = cycles.split_at(1);
                    tube_triangles(&c1[0], &c2[0], &mut fan, &mut positions);
                } else {
                    for cycle in &cycles[..n_cycles] {
                        triangulate(cycle, &mut tri_buf, &mut positions);
                        fan.extend_from_slice(&tri_buf);
                    }
                }
                for tri in &fan {
                    if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
                        continue;
                    }
                    triangles.push(match opts.inside {
                        Inside::Above => *tri,
                        Inside::Below => [tri[0], tri[2], tri[1]],
                    });
                }
            }
        }
    }
    Ok(TriMesh { positions, triangles })
}

/// Corner of this module (bit 0 → axis 0, bit 1 → axis 1, bit 2 → axis 2) for each corner of
/// the classic table's numbering, (x, y, z) = 0 (0,0,0), 1 (1,0,0), 2 (1,1,0), 3 (0,1,0), then
/// the same at z = 1. skimage puts the table's x along array axis 2 and z along axis 0 (found
/// by trying the 48 symmetries of the cube against skimage on all 254 cases; only this one
/// gives its triangles in every case).
const CLASSIC_CORNER: [usize; 8] = [0, 4, 6, 2, 1, 5, 7, 3];

/// This module's local edge for each edge of the classic table's numbering: 0–3 the cycle of
/// corners 0-1-2-3, 4–7 the cycle 4-5-6-7, 8–11 the edges from corner c to c + 4.
const CLASSIC_EDGE: [usize; 12] = {
    let mut out = [0usize; 12];
    let mut e = 0;
    while e < 12 {
        let (p, q) = if e < 4 {
            (e, (e + 1) % 4)
        } else if e < 8 {
            (e, 4 + (e - 3) % 4)
        } else {
            (e - 8, e - 4)
        };
        out[e] = edge_of(CLASSIC_CORNER[p], CLASSIC_CORNER[q]);
        e += 1;
    }
    out
};

/// The classic 256-case table's triangles for a cell whose above corners are `mask` (this
/// module's corner bits), as local vertices (`local_vertex[e]` for local edge `e`), oriented
/// like this module's polygons for [`Inside::Above`]. Returns false (and leaves `out` alone)
/// if a table edge has no vertex, which cannot happen when the cell's crossed edges are the
/// table's.
///
/// The table is `marching_cubes::tables::TRI_TABLE` (Paul Bourke's listing of the Lorensen–
/// Cline table, the one scikit-image's `method="lorensen"` uses and whose triangulations
/// its `"lewiner"` tables share in the unambiguous cases): it is data that fixes which
/// diagonals split each polygon, and using it makes the triangles, not only the polygons,
/// those of skimage. It is indexed, as skimage does, by the corners above the level (so an
/// ambiguous face separates its above corners), and with skimage's axis order its triangles
/// already turn the way this module's polygons do (the unit test below checks both).
fn classic_triangles(mask: u32, local_vertex: &[u32; 12], out: &mut Vec<[u32; 3]>) -> bool {
    let mut index = 0usize;
    for (b, &c) in CLASSIC_CORNER.iter().enumerate() {
        if mask & (1 << c) != 0 {
            index |= 1 << b;
        }
    }
    let row = &marching_cubes::tables::TRI_TABLE[index];
    let start = out.len();
    for t in row.chunks_exact(3) {
        if t[0] < 0 {
            break;
        }
        let v = |k: usize| usize::try_from(t[k]).ok().and_then(|e| CLASSIC_EDGE.get(e)).map(|&e| local_vertex[e]);
        match (v(0), v(1), v(2)) {
            (Some(a), Some(b), Some(c)) if a != u32::MAX && b != u32::MAX && c != u32::MAX => out.push([a, b, c]),
            _ => {
                out.truncate(start);
                return false;
            }
        }
    }
    true
}

/// The segments the cell's faces contribute (`succ[entry edge] = exit edge`, `usize::MAX`
/// for an edge without crossing), the faces with diagonal above and below corners (bits as
/// in [`FACES`]), and those of them whose above corners were joined. `v`: corner values minus
/// the level; `mask`: above corners.
fn face_segments(v: &[f64; 8], mask: u32, ambiguity: Ambiguity) -> ([usize; 12], u8, u8) {
    let above = |c: usize| mask & (1 << c) != 0;
    // Face segments: succ[entry edge] = exit edge.
    let mut succ = [usize::MAX; 12];
    // Ambiguous faces whose above corners are joined.
    let mut joined_faces = 0u8;
    let mut ambiguous_faces = 0u8;
    for (fi, face) in FACES.iter().enumerate() {
        // Crossings in counter-clockwise order; `true` = entering the above region.
        let mut cross = [(0usize, false); 4];
        let mut n = 0;
        for q in 0..4 {
            let (a, b) = (face[q], face[(q + 1) % 4]);
            if above(a) != above(b) {
                cross[n] = (edge_of(a, b), above(b));
                n += 1;
            }
        }
        match n {
            0 => {}
            2 => {
                let (e, x) = if cross[0].1 { (cross[0].0, cross[1].0) } else { (cross[1].0, cross[0].0) };
                succ[e] = x;
            }
            _ => {
                // Rotate so the sequence is entry, exit, entry, exit.
                let r = if cross[0].1 { 0 } else { 1 };
                let (e1, x1, e2, x2) = (cross[r].0, cross[(r + 1) % 4].0, cross[(r + 2) % 4].0, cross[(r + 3) % 4].0);
                let join = match ambiguity {
                    Ambiguity::SeparateAbove => false,
                    Ambiguity::JoinAbove => true,
                    Ambiguity::AsymptoticDecider => {
                        let (a, b, c, d) = (v[face[0]], v[face[1]], v[face[2]], v[face[3]]);
                        // Above pair (a, c) or (b, d); joined iff the saddle is above.
                        if a > 0.0 {
                            a * c - b * d > 0.0
                        } else {
                            b * d - a * c > 0.0
                        }
                    }
                };
                ambiguous_faces |= 1 << fi;
                if join {
                    joined_faces |= 1 << fi;
                    succ[e1] = x2;
                    succ[e2] = x1;
                } else {
                    succ[e1] = x1;
                    succ[e2] = x2;
                }
            }
        }
    }
    (succ, joined_faces, ambiguous_faces)
}

/// The 12 cube edges as corner pairs.
const CUBE_EDGES: [(usize, usize); 12] =
    [(0, 1), (2, 3), (4, 5), (6, 7), (0, 2), (1, 3), (4, 6), (5, 7), (0, 4), (1, 5), (2, 6), (3, 7)];

fn find(p: &mut [usize], mut x: usize) -> usize {
    while p[x] != x {
        p[x] = p[p[x]];
        x = p[x];
    }
    x
}

fn union(p: &mut [usize], a: usize, b: usize) {
    let (ra, rb) = (find(p, a), find(p, b));
    if ra != rb {
        p[ra.max(rb)] = ra.min(rb);
    }
}

/// Whether the cell's two polygons bound two regions of one sign (two components of that
/// sign on the cube's surface, one of the other) that the trilinear interpolant connects
/// through the cell's interior. `v`: corner values minus the level; `mask`: above corners;
/// `joined`/`ambiguous`: faces (bits as in [`FACES`]) with two diagonal above corners, and
/// those of them whose above corners the face decision joined.
fn joined_inside(v: &[f64; 8], mask: u32, joined: u8, ambiguous: u8) -> bool {
    for above in [true, false] {
        let is_s = |c: usize| (mask & (1 << c) != 0) == above;
        let comp_of = |s: bool| {
            let mut p: [usize; 8] = std::array::from_fn(|i| i);
            for &(a, b) in &CUBE_EDGES {
                if is_s(a) == s && is_s(b) == s {
                    union(&mut p, a, b);
                }
            }
            for (f, face) in FACES.iter().enumerate() {
                if ambiguous & (1 << f) != 0 {
                    // The face's above diagonal is joined iff `joined`, its below one iff not;
                    // the set being built is the above sign iff `s == above`.
                    let join_s = (joined & (1 << f) != 0) == (s == above);
                    if join_s {
                        let (a, c) = if is_s(face[0]) == s { (face[0], face[2]) } else { (face[1], face[3]) };
                        union(&mut p, a, c);
                    }
                }
            }
            let mut roots = [usize::MAX; 8];
            let mut n = 0;
            for c in 0..8 {
                if is_s(c) == s {
                    let r = find(&mut p, c);
                    if !roots[..n].contains(&r) {
                        roots[n] = r;
                        n += 1;
                    }
                }
            }
            (n, p)
        };
        let (n_s, mut p) = comp_of(true);
        let (n_o, _) = comp_of(false);
        if n_s != 2 || n_o != 1 {
            continue;
        }
        // Corner sets of the two components.
        let first = (0..8).find(|&c| is_s(c)).unwrap_or(0);
        let r0 = find(&mut p, first);
        let mut comp = [0u8; 2];
        for c in 0..8 {
            if is_s(c) {
                comp[(find(&mut p, c) != r0) as usize] |= 1 << c;
            }
        }
        // Sign so that the two regions are where g > 0 (below: v ≤ 0, taken as −v > 0).
        let g: [f64; 8] = std::array::from_fn(|c| if above { v[c] } else { -v[c] });
        return connected_in_cube(&g, comp[0], comp[1]);
    }
    false
}

/// Whether corners in `a` and corners in `b` (bit sets, every corner with `g > 0`) lie in one
/// component of `{g > 0}` for the trilinear interpolant `g` of the unit cube.
///
/// Exact sweep along axis 2: each slice is bilinear, and every component of a bilinear
/// slice's positive set contains a positive slice corner; the slice topology changes only
/// where a slice corner crosses 0 (≤ 4 heights) or the slice's saddle does (the roots of the
/// quadratic `A·C − B·D`, ≤ 2). Between those heights components are tracked by the slice
/// corners they contain, and continue across a height through every corner positive on both
/// sides.
fn connected_in_cube(g: &[f64; 8], a: u8, b: u8) -> bool {
    // Slice corner q (bits: axis 0, axis 1) at height t: g[q] + (g[q + 4] − g[q]) t.
    let mut events = [0.0f64; 8];
    let mut ne = 0;
    let mut push = |t: f64, events: &mut [f64; 8]| {
        if t > 0.0 && t < 1.0 && t.is_finite() {
            events[ne] = t;
            ne += 1;
        }
    };
    for q in 0..4 {
        let (g0, g1) = (g[q], g[q + 4]);
        if (g0 > 0.0) != (g1 > 0.0) {
            push(g0 / (g0 - g1), &mut events);
        }
    }
    // det(t) = A C − B D with A = q0, B = q1, C = q3, D = q2 (cyclic order 0, 1, 3, 2).
    let d = |q: usize| g[q + 4] - g[q];
    let c0 = g[0] * g[3] - g[1] * g[2];
    let c1 = g[0] * d(3) + g[3] * d(0) - g[1] * d(2) - g[2] * d(1);
    let c2 = d(0) * d(3) - d(1) * d(2);
    if c2 != 0.0 {
        let disc = c1 * c1 - 4.0 * c2 * c0;
        if disc >= 0.0 {
            let sq = disc.sqrt();
            push((-c1 - sq) / (2.0 * c2), &mut events);
            push((-c1 + sq) / (2.0 * c2), &mut events);
        }
    } else if c1 != 0.0 {
        push(-c0 / c1, &mut events);
    }
    let ev = &mut events[..ne];
    ev.sort_by(f64::total_cmp);
    let mut bounds = [0.0f64; 10];
    bounds[0] = 0.0;
    bounds[1..=ne].copy_from_slice(ev);
    bounds[ne + 1] = 1.0;
    let n_int = ne + 1;
    let mut p: [usize; 40] = std::array::from_fn(|i| i);
    let mut prev_pos = [false; 4];
    for k in 0..n_int {
        let t = 0.5 * (bounds[k] + bounds[k + 1]);
        let s: [f64; 4] = std::array::from_fn(|q| g[q] + (g[q + 4] - g[q]) * t);
        let pos: [bool; 4] = std::array::from_fn(|q| s[q] > 0.0);
        for (x, y) in [(0, 1), (1, 3), (3, 2), (2, 0)] {
            if pos[x] && pos[y] {
                union(&mut p, 4 * k + x, 4 * k + y);
            }
        }
        if pos[0] && pos[3] && !pos[1] && !pos[2] && s[0] * s[3] - s[1] * s[2] > 0.0 {
            union(&mut p, 4 * k, 4 * k + 3);
        }
        if pos[1] && pos[2] && !pos[0] && !pos[3] && s[1] * s[2] - s[0] * s[3] > 0.0 {
            union(&mut p, 4 * k + 1, 4 * k + 2);
        }
        if k > 0 {
            for q in 0..4 {
                if pos[q] && prev_pos[q] {
                    union(&mut p, 4 * (k - 1) + q, 4 * k + q);
                }
            }
        }
        prev_pos = pos;
    }
    // Cube corner c: slice corner c & 3 in the first (c < 4) or last interval.
    let node = |c: usize| if c < 4 { c } else { 4 * (n_int - 1) + (c - 4) };
    for ca in (0..8).filter(|&c| a & (1 << c) != 0) {
        for cb in (0..8).filter(|&c| b & (1 << c) != 0) {
            let (x, y) = (node(ca), node(cb));
            if find(&mut p, x) == find(&mut p, y) {
                return true;
            }
        }
    }
    false
}

/// A tube joining two polygons whose oriented edges it keeps as its boundary: a ring of
/// new vertices halfway between `c1` and the cell's middle (so that no tube edge lies in a
/// cell face), a strip from `c1` to the ring, a strip from the ring to `c2`.
fn tube_triangles(c1: &[(u32, u8)], c2: &[(u32, u8)], out: &mut Vec<[u32; 3]>, positions: &mut Vec<[f64; 3]>) {
    let centroid = |c: &[(u32, u8)], positions: &Vec<[f64; 3]>| {
        let mut m = [0.0; 3];
        for &(v, _) in c {
            for k in 0..3 {
                m[k] += positions[v as usize][k] / c.len() as f64;
            }
        }
        m
    };
    let (m1, m2) = (centroid(c1, positions), centroid(c2, positions));
    let mid: [f64; 3] = std::array::from_fn(|k| 0.5 * (m1[k] + m2[k]));
    let a: Vec<u32> = c1.iter().map(|c| c.0).collect();
    let ring: Vec<u32> = a
        .iter()
        .map(|&v| {
            let p = positions[v as usize];
            positions.push(std::array::from_fn(|k| 0.5 * (p[k] + mid[k])));
            (positions.len() - 1) as u32
        })
        .collect();
    // Strip c1[i] → c1[i + 1] → ring[i + 1] → ring[i].
    let n = a.len();
    for i in 0..n {
        let j = (i + 1) % n;
        out.push([a[i], a[j], ring[j]]);
        out.push([a[i], ring[j], ring[i]]);
    }
    let b: Vec<u32> = c2.iter().map(|c| c.0).collect();
    zipper(&ring, &b, out, positions);
}

/// Triangles of the annulus whose oriented boundary is `a` and `b`, both as given (they
/// must run in opposite senses around the annulus; at least 3 vertices each): `a` walked
/// forwards, `b` backwards, from their closest pair of vertices, the two advancing evenly
/// (so that no diagonal is used twice).
fn zipper(a: &[u32], b: &[u32], out: &mut Vec<[u32; 3]>, positions: &[[f64; 3]]) {
    let (na, nb) = (a.len(), b.len());
    let dist = |x: u32, y: u32| {
        let (p, q) = (positions[x as usize], positions[y as usize]);
        (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)
    };
    let mut best = (f64::INFINITY, 0, 0);
    for (i, &ai) in a.iter().enumerate() {
        for (j, &bj) in b.iter().enumerate() {
            let d = dist(ai, bj);
            if d < best.0 {
                best = (d, i, j);
            }
        }
    }
    let (_, mut i, mut j) = best;
    let (mut left_a, mut left_b) = (na, nb);
    while left_a + left_b > 0 {
        let (ai, ai1) = (a[i % na], a[(i + 1) % na]);
        let (bj, bj1) = (b[j % nb], b[(j + nb - 1) % nb]);
        let (done_a, done_b) = (na - left_a, nb - left_b);
        let advance_a = left_b == 0 || (left_a > 0 && (2 * done_a + 1) * nb < (2 * done_b + 1) * na);
        if advance_a {
            out.push([ai, ai1, bj]);
            i = (i + 1) % na;
            left_a -= 1;
        } else {
            out.push([bj1, bj, ai]);
            j = (j + nb - 1) % nb;
            left_b -= 1;
        }
    }
}

/// Triangles of one polygon (vertex, faces of the cell it lies on) oriented as given: a fan
/// from the first corner whose diagonals all leave the cell's faces (a diagonal between two
/// points of one face would lie in that face, where the neighbouring cell may put the same
/// segment: a non-manifold edge), else a fan around a new vertex at the polygon's centroid,
/// inside the cell.
fn triangulate(cycle: &[(u32, u8)], out: &mut Vec<[u32; 3]>, positions: &mut Vec<[f64; 3]>) {
    out.clear();
    let n = cycle.len();
    if n < 3 {
        return;
    }
    'start: for s in 0..n {
        let apex = cycle[s];
        for t in 2..n - 1 {
            if apex.1 & cycle[(s + t) % n].1 != 0 {
                continue 'start;
            }
        }
        for t in 1..n - 1 {
            out.push([apex.0, cycle[(s + t) % n].0, cycle[(s + t + 1) % n].0]);
        }
        return;
    }
    let mut c = [0.0; 3];
    for &(v, _) in cycle {
        for k in 0..3 {
            c[k] += positions[v as usize][k];
        }
    }
    positions.push(c.map(|x| x / n as f64));
    let centre = (positions.len() - 1) as u32;
    for t in 0..n {
        out.push([centre, cycle[t].0, cycle[(t + 1) % n].0]);
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeSet;

    /// For all 256 cases: the classic table's triangles (vertex = local edge) have exactly the
    /// directed boundary of the polygons `face_segments` builds with every face separating its
    /// above corners, so the table agrees with this module's faces and orientation, and every
    /// interior diagonal is used by exactly two triangles and lies off the cube's faces.
    #[test]
    fn classic_table_triangulates_the_separate_above_polygons() {
        let ids: [u32; 12] = std::array::from_fn(|e| e as u32);
        for mask in 1u32..255 {
            let v: [f64; 8] = std::array::from_fn(|c| if mask & (1 << c) != 0 { 1.0 } else { -1.0 });
            let (succ, joined, _) = face_segments(&v, mask, Ambiguity::SeparateAbove);
            assert_eq!(joined, 0);
            let polygon: BTreeSet<(u32, u32)> =
                (0..12).filter(|&e| succ[e] != usize::MAX).map(|e| (e as u32, succ[e] as u32)).collect();
            let mut local = [u32::MAX; 12];
            for e in 0..12 {
                if succ[e] != usize::MAX {
                    local[e] = ids[e];
                }
            }
            let mut tris = Vec::new();
            assert!(classic_triangles(mask, &local, &mut tris), "case {mask:#010b}: table edge without crossing");
            let directed: Vec<(u32, u32)> =
                tris.iter().flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])]).collect();
            let set: BTreeSet<(u32, u32)> = directed.iter().copied().collect();
            assert_eq!(set.len(), directed.len(), "case {mask:#010b}: a directed edge used twice");
            let boundary: BTreeSet<(u32, u32)> = set.iter().copied().filter(|&(a, b)| !set.contains(&(b, a))).collect();
            assert_eq!(boundary, polygon, "case {mask:#010b}");
            let faces = |e: u32| edge_face_mask(e as usize);
            for &(a, b) in set.difference(&boundary) {
                assert_eq!(faces(a) & faces(b), 0, "case {mask:#010b}: diagonal {a}-{b} lies in a cube face");
            }
        }
    }
}
