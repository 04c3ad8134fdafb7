//! The phases of the certified search before the first split (see the module doc of
//! [`crate::hausdorff`]): exact distances of source vertices (phase 1), pass A (every
//! source triangle bounded without a BVH query), pass B (the unsettled triangles made
//! exact, those with the largest bounds first) and the greedy probe between pass B's two
//! halves. Every step works on fixed chunks, so results do not depend on the thread count.

use std::collections::HashMap;

use occupancy::distance::closest_point_triangle::closest_point_triangle;
use occupancy::Workspace;
use rayon::prelude::*;
use vf_common::vec3::distance;

use super::cell::{Cell, Engine, UNIT_BARY};
use super::mesh::{query_points, DistanceMesh};
use super::{CHUNK, V3};

/// An unsettled source triangle after pass A: (bound so far, direction, triangle).
pub(super) type Pending = (f64, u8, u32);

/// A witness: the distance, the source point attaining it, its direction.
pub(super) type Witness = (f64, V3, u8);

/// Exact distance and closest target triangle of every source vertex, per direction;
/// distance −1 for a vertex not queried in phase 1.
pub(super) type VertexDistances = [Vec<(f64, u32)>; 2];

/// Output of pass A on one chunk: cells with all corners exact, pending triangles, largest
/// discarded bound.
type PassA = (Vec<Cell>, Vec<Pending>, f64);

/// Output of pass B on a group of pending triangles.
#[derive(Default)]
pub(super) struct PassB {
    pub(super) cells: Vec<Cell>,
    pub(super) max_discarded: f64,
    /// Largest new exact distance per direction, with its point.
    pub(super) witness: [(f64, V3); 2],
    pub(super) queries: u64,
}

/// Exact distances (and closest triangles) of source vertices queried by one group of
/// pending triangles, keyed by (direction, vertex).
type VertexCache = HashMap<(u8, u32), (f64, u32)>;

/// Cells probed greedily for a better lower bound before pass B's bulk.
const PROBE_CELLS: usize = 32;

/// Pass B first settles this many pending triangles with the largest bounds.
const TOP_PENDING: usize = 1024;

/// Phase 1 queries every VERTEX_STRIDE-th vertex of a large source exactly.
const VERTEX_STRIDE: usize = 16;

/// Result of phase 1.
pub(super) struct VertexPhase {
    pub(super) vert: VertexDistances,
    /// Largest squared distance of any queried vertex, referenced or not.
    pub(super) libigl_sq: f64,
    /// Whether every vertex of every direction was queried.
    pub(super) all_exact: bool,
    /// Largest distance of a referenced vertex (`−∞` if none).
    pub(super) witness: Witness,
    pub(super) directed_witness: [f64; 2],
    pub(super) queries: u64,
}

/// Phase 1: exact distances of source vertices. Every vertex when asked (the libigl value)
/// or when the source is small next to the target; otherwise every VERTEX_STRIDE-th
/// referenced vertex, enough for a good first lower bound.
pub(super) fn query_vertices(engine: &Engine, dirs: &[u8], all_vertices: bool) -> VertexPhase {
    let mut out = VertexPhase {
        vert: [Vec::new(), Vec::new()],
        libigl_sq: 0.0,
        all_exact: true,
        witness: (f64::NEG_INFINITY, [0.0; 3], 0),
        directed_witness: [0.0; 2],
        queries: 0,
    };
    for &dir in dirs {
        let (src, tgt) = (engine.src[dir as usize], engine.tgt[dir as usize]);
        let nv = src.mesh.positions.len();
        let mut referenced = vec![false; nv];
        for t in &src.mesh.triangles {
            for &v in t {
                referenced[v as usize] = true;
            }
        }
        let full = all_vertices || nv <= tgt.mesh.positions.len() / 4 || nv <= 4 * VERTEX_STRIDE;
        let idx: Vec<usize> = if full {
            (0..nv).collect()
        } else {
            out.all_exact = false;
            (0..nv).filter(|&v| referenced[v]).step_by(VERTEX_STRIDE).collect()
        };
        let pts: Vec<V3> = idx.iter().map(|&v| src.mesh.positions[v]).collect();
        let r = query_points(tgt, &pts);
        out.queries += r.len() as u64;
        let mut d = vec![(-1.0, 0u32); nv];
        for (&v, &(d2, t)) in idx.iter().zip(&r) {
            out.libigl_sq = out.libigl_sq.max(d2);
            let dv = d2.sqrt();
            d[v] = (dv, t);
            if referenced[v] {
                out.directed_witness[dir as usize] = out.directed_witness[dir as usize].max(dv);
                if dv > out.witness.0 {
                    out.witness = (dv, src.mesh.positions[v], dir);
                }
            }
        }
        out.vert[dir as usize] = d;
    }
    out
}

/// Output of pass A over every direction.
pub(super) struct PassAResult {
    /// Triangles with all corners exact whose full bound exceeds `lo + tol`.
    pub(super) active: Vec<Cell>,
    /// Triangles not settled by the cheap bound.
    pub(super) pending: Vec<Pending>,
    pub(super) max_discarded: f64,
    pub(super) cells_evaluated: u64,
}

/// Pass A (no BVH query): every source triangle, in Morton order of its centroid. With all
/// three corners exact, its full upper bound; otherwise the convexity bound against the
/// closest target triangle of the nearest exactly known corner seen so far in its chunk
/// (three point-triangle distances), which settles most triangles.
pub(super) fn pass_a(engine: &Engine, dirs: &[u8], vert: &VertexDistances, lo0: f64, tol: f64) -> PassAResult {
    let mut out =
        PassAResult { active: Vec::new(), pending: Vec::new(), max_discarded: f64::NEG_INFINITY, cells_evaluated: 0 };
    for &dir in dirs {
        let src = engine.src[dir as usize];
        let centroids: Vec<V3> = src
            .mesh
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| src.mesh.positions[v as usize]);
                [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0)
            })
            .collect();
        let order = occupancy::order::morton_order(&centroids);
        let parts: Vec<PassA> =
            order.par_chunks(CHUNK).map(|idx| pass_a_chunk(engine, dir, &vert[dir as usize], idx, lo0 + tol)).collect();
        out.cells_evaluated += src.mesh.triangles.len() as u64;
        for (cells, pend, disc) in parts {
            out.active.extend(cells);
            out.pending.extend(pend);
            out.max_discarded = out.max_discarded.max(disc);
        }
    }
    out
}

/// Pass A on one chunk of source triangles `idx` of direction `dir`; a bound at most
/// `keep_above` settles a triangle.
fn pass_a_chunk(engine: &Engine, dir: u8, vd: &[(f64, u32)], idx: &[u32], keep_above: f64) -> PassA {
    let (src, tgt) = (engine.src[dir as usize], engine.tgt[dir as usize]);
    let mut cells = Vec::new();
    let mut pend = Vec::new();
    let mut disc = f64::NEG_INFINITY;
    let mut last_t: Option<u32> = None;
    for &ti in idx {
        let tri = src.mesh.triangles[ti as usize];
        let x = tri.map(|v| src.mesh.positions[v as usize]);
        let known = tri.map(|v| vd[v as usize]);
        if let Some(k) = known.iter().find(|k| k.0 >= 0.0) {
            last_t = Some(k.1);
        }
        if known.iter().all(|k| k.0 >= 0.0) {
            let (d, t) = (known.map(|k| k.0), known.map(|k| k.1));
            let ub = engine.upper_bound(dir, &x, &d, &t);
            if ub > keep_above {
                cells.push(Cell { dir, tri: ti, bary: UNIT_BARY, d, t, ub });
            } else {
                disc = disc.max(ub);
            }
            continue;
        }
        let m = match last_t {
            Some(t) => max_corner_distance(tgt, t, &x, f64::INFINITY),
            None => f64::INFINITY,
        };
        if m > keep_above {
            pend.push((m, dir, ti));
        } else {
            disc = disc.max(m);
        }
    }
    (cells, pend, disc)
}

/// Largest distance of the corners `x` to target triangle `t` (an upper bound of the
/// distance over the source triangle, by convexity), stopping as soon as it exceeds
/// `stop_above`.
fn max_corner_distance(tgt: &DistanceMesh, t: u32, x: &[V3; 3], stop_above: f64) -> f64 {
    let tc = tgt.corners(t);
    let mut m = 0.0f64;
    for &xj in x {
        m = m.max(distance(xj, closest_point_triangle(xj, tc[0], tc[1], tc[2])));
        if m > stop_above {
            break;
        }
    }
    m
}

/// Indices (ascending) of the TOP_PENDING pending triangles with the largest bounds.
pub(super) fn top_pending(pending: &[Pending]) -> Vec<usize> {
    let mut top: Vec<usize> = (0..pending.len()).collect();
    let k = TOP_PENDING.min(top.len());
    if k < top.len() {
        top.select_nth_unstable_by(k, |&a, &b| pending[b].0.total_cmp(&pending[a].0).then(a.cmp(&b)));
    }
    top.truncate(k);
    top.sort_unstable();
    top
}

/// The source side of pass B: the engine, phase 1's vertex distances and pass A's pending
/// triangles.
pub(super) struct PassBInput<'e, 'a> {
    pub(super) engine: &'e Engine<'a>,
    pub(super) vert: &'e VertexDistances,
    pub(super) pending: &'e [Pending],
}

impl PassBInput<'_, '_> {
    /// Exact corner distances of pending triangle `ti` (from phase 1, the group's cache of
    /// vertices already queried, or a BVH query) and its full bound (at most `m`, its bound
    /// from pass A); also the closest target triangle of its first corner.
    fn exact_cell(
        &self,
        dir: u8,
        ti: u32,
        m: f64,
        ws: &mut Workspace,
        out: &mut PassB,
        cache: &mut VertexCache,
    ) -> (Cell, u32) {
        let (src, tgt) = (self.engine.src[dir as usize], self.engine.tgt[dir as usize]);
        let vd = &self.vert[dir as usize];
        let tri = src.mesh.triangles[ti as usize];
        let x = tri.map(|v| src.mesh.positions[v as usize]);
        let mut d = [0.0; 3];
        let mut t = [0u32; 3];
        for j in 0..3 {
            let (dv, tv) = vd[tri[j] as usize];
            if dv >= 0.0 {
                (d[j], t[j]) = (dv, tv);
            } else if let Some(&(dc, tc)) = cache.get(&(dir, tri[j])) {
                (d[j], t[j]) = (dc, tc);
            } else {
                let c = tgt.bvh.closest_point(x[j], ws);
                out.queries += 1;
                (d[j], t[j]) = (c.squared_distance.sqrt(), c.triangle);
                cache.insert((dir, tri[j]), (d[j], t[j]));
                if d[j] > out.witness[dir as usize].0 {
                    out.witness[dir as usize] = (d[j], x[j]);
                }
            }
        }
        let ub = self.engine.upper_bound(dir, &x, &d, &t).min(m);
        (Cell { dir, tri: ti, bary: UNIT_BARY, d, t, ub }, t[0])
    }

    /// Pass B, first half: the pending triangles `top` made exact (all kept as cells), in
    /// groups of 64; their exact corner distances raise the lower bound.
    pub(super) fn top(&self, top: &[usize]) -> Vec<PassB> {
        top.par_chunks(64)
            .map(|part| {
                let mut ws = Workspace::new();
                let mut out = PassB::default();
                let mut cache = VertexCache::default();
                for &i in part {
                    let (m, dir, ti) = self.pending[i];
                    let (cell, _) = self.exact_cell(dir, ti, m, &mut ws, &mut out, &mut cache);
                    out.cells.push(cell);
                }
                out
            })
            .collect()
    }

    /// Pass B, second half: the pending triangles `rest` in Morton order, in chunks, each
    /// first tested against the closest target triangle of the previous exactly queried
    /// corner in its chunk, and only then queried exactly. `lo` is the lower bound so far.
    pub(super) fn rest(&self, rest: &[usize], lo: f64, tol: f64) -> Vec<PassB> {
        rest.par_chunks(CHUNK).map(|part| self.rest_chunk(part, lo, tol)).collect()
    }

    /// [`Self::rest`] on one chunk; the chunk's own lower bound rises with its queries.
    fn rest_chunk(&self, part: &[usize], lo: f64, tol: f64) -> PassB {
        let mut ws = Workspace::new();
        let mut out = PassB::default();
        let mut cache = VertexCache::default();
        let mut local_lo = lo;
        let mut last_t: Option<(u8, u32)> = None;
        for &i in part {
            let (m, dir, ti) = self.pending[i];
            if m <= local_lo + tol {
                out.max_discarded = out.max_discarded.max(m);
                continue;
            }
            if let Some((_, t)) = last_t.filter(|l| l.0 == dir) {
                let src = self.engine.src[dir as usize];
                let x = src.mesh.triangles[ti as usize].map(|v| src.mesh.positions[v as usize]);
                let mm = max_corner_distance(self.engine.tgt[dir as usize], t, &x, local_lo + tol);
                if mm <= local_lo + tol {
                    out.max_discarded = out.max_discarded.max(mm);
                    continue;
                }
            }
            let (cell, t0) = self.exact_cell(dir, ti, m, &mut ws, &mut out, &mut cache);
            local_lo = local_lo.max(out.witness[dir as usize].0);
            last_t = Some((dir, t0));
            if cell.ub > local_lo + tol {
                out.cells.push(cell);
            } else {
                out.max_discarded = out.max_discarded.max(cell.ub);
            }
        }
        out
    }
}

/// Probe: from the PROBE_CELLS cells with the largest bounds so far, descend greedily into
/// the child with the largest bound; the midpoints met on the way are real distances near
/// the likely maximiser, which raise the lower bound before the bulk of the work. Returns
/// per probe the largest midpoint distance, its point and direction, and the queries made.
pub(super) fn probe(engine: &Engine, active: &[Cell], lo: f64, tol: f64, max_depth: u32) -> Vec<(f64, V3, u8, u64)> {
    let mut order: Vec<usize> = (0..active.len()).collect();
    order.sort_unstable_by(|&i, &j| active[j].ub.total_cmp(&active[i].ub).then(i.cmp(&j)));
    order.truncate(PROBE_CELLS);
    order
        .par_iter()
        .map(|&i| {
            let mut ws = Workspace::new();
            let mut cur = active[i];
            let mut best = (f64::NEG_INFINITY, [0.0; 3], cur.dir, 0u64);
            for _ in 0..max_depth {
                if cur.ub <= lo + tol || cur.ub <= best.0 + tol {
                    break;
                }
                let (children, md, mx) = engine.split(&cur, &mut ws);
                best.3 += 3;
                if md > best.0 {
                    (best.0, best.1) = (md, mx);
                }
                cur = children.into_iter().max_by(|a, b| a.ub.total_cmp(&b.ub)).unwrap_or(cur);
            }
            best
        })
        .collect()
}
