//! Incremental construction: Bowyer–Watson cavity insertion (Bowyer 1981, Watson 1981)
//! with an infinite vertex, remembering stochastic visibility walk for point location
//! (Devillers, Pion & Teillaud 2002, "Walking in a triangulation", IJFCS 13(2)), and the
//! exact perturbed predicates of [`crate::predicates`].
//!
//! Topology only lives here: tetrahedra are `[u32; 4]` vertex ids (the infinite vertex
//! [`INFINITE`] only ever at index 3) and neighbours are `[u32; 4]` encoded as
//! `tet * 4 + face`, where neighbour `i` is across the facet opposite vertex `i` and
//! `face` is that facet's index in the neighbour. All tetrahedra are positively oriented
//! (see [`crate::predicates::orient`]); an infinite tetrahedron `(a, b, c, ∞)` has the
//! convex hull on the negative side of `abc`.

use crate::error::DelaunayError;
use crate::predicates::{in_conflict_finite, in_conflict_infinite, orient, Point};

/// Id of the infinite vertex.
pub const INFINITE: u32 = u32::MAX;
const NONE: u32 = u32::MAX;
/// Tetrahedron ids must fit in 30 bits (neighbour encoding `tet * 4 + face`).
pub(crate) const MAX_TETS: usize = 1 << 30;

/// For a new tetrahedron whose boundary facet is opposite `face` (the new point sits at
/// index `face`), the face `j != face` contains the new point and the two vertices at
/// `OTHER[face][j]`.
const OTHER: [[(usize, usize); 4]; 4] = {
    let mut t = [[(0usize, 0usize); 4]; 4];
    let mut f = 0;
    while f < 4 {
        let mut j = 0;
        while j < 4 {
            let mut a = 4;
            let mut b = 4;
            let mut k = 0;
            while k < 4 {
                if k != f && k != j {
                    if a == 4 {
                        a = k;
                    } else {
                        b = k;
                    }
                }
                k += 1;
            }
            t[f][j] = (a, b);
            j += 1;
        }
        f += 1;
    }
    t
};

/// One tetrahedron: vertex ids and encoded neighbours side by side (one 32-byte,
/// aligned record, so a neighbour visit touches one cache line).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(32))]
pub(crate) struct Cell {
    /// Vertex ids; [`INFINITE`] only at index 3.
    pub v: [u32; 4],
    /// Neighbour across the facet opposite vertex `i`, encoded `tet * 4 + face`.
    pub n: [u32; 4],
}

#[derive(Clone, Copy, Default)]
struct EdgeSlot {
    key: u64,
    value: u32,
    stamp: u32,
}

#[derive(Clone, Copy)]
struct BoundaryFacet {
    /// The new tetrahedron: the cavity tetrahedron with vertex `face` replaced by the
    /// new point.
    verts: [u32; 4],
    face: u32,
    /// Encoded neighbour outside the cavity.
    outer: u32,
}

/// The mutable triangulation during construction. Vertex ids are indices into `pts`.
pub(crate) struct Builder<'a> {
    pts: &'a [Point],
    far: f64,
    cells: Vec<Cell>,
    mark: Vec<u32>,
    free: Vec<u32>,
    stamp: u32,
    rng: u32,
    last: u32,
    stack: Vec<u32>,
    cavity: Vec<u32>,
    boundary: Vec<BoundaryFacet>,
    table: Vec<EdgeSlot>,
    table_stamp: u32,
}

/// Result of [`Builder::insert`].
pub(crate) enum Inserted {
    New,
    /// The point coincides with this existing vertex.
    Duplicate(u32),
}

impl<'a> Builder<'a> {
    /// Start from the positively oriented or negatively oriented tetrahedron `init`
    /// (four affinely independent vertex ids) and its four infinite neighbours.
    pub fn new(pts: &'a [Point], far: f64, init: [u32; 4]) -> Self {
        let capacity = pts.len() * 7 + 16;
        let mut b = Builder {
            pts,
            far,
            cells: Vec::with_capacity(capacity),
            mark: Vec::with_capacity(capacity),
            free: Vec::new(),
            stamp: 0,
            rng: 0x2545_F491,
            last: 0,
            stack: Vec::new(),
            cavity: Vec::new(),
            boundary: Vec::new(),
            table: vec![EdgeSlot::default(); 256],
            table_stamp: 0,
        };
        let [a, bb, c, d] = init;
        let p = |v: u32| &pts[v as usize];
        let t0 = match orient(p(a), p(bb), p(c), p(d)) {
            1 => [a, bb, c, d],
            -1 => [bb, a, c, d],
            _ => panic!("Builder::new: initial tetrahedron is flat"),
        };
        // Facet opposite vertex i, oriented with v_i on its positive side; the infinite
        // tetrahedron takes the reverse orientation (∞ on the positive side).
        let facets: [[usize; 3]; 4] = [[1, 3, 2], [0, 2, 3], [0, 3, 1], [0, 1, 2]];
        let mut all = vec![t0];
        for f in facets {
            all.push([t0[f[0]], t0[f[2]], t0[f[1]], INFINITE]);
        }
        for t in &all {
            b.cells.push(Cell { v: *t, n: [NONE; 4] });
            b.mark.push(0);
        }
        // Brute-force adjacency of the 5 initial tetrahedra.
        for i in 0..5 {
            for j in 0..5 {
                if i == j {
                    continue;
                }
                let (ti, tj) = (all[i], all[j]);
                let shared = ti.iter().filter(|v| tj.contains(v)).count();
                if shared == 3 {
                    let fi = (0..4).find(|&k| !tj.contains(&ti[k])).unwrap();
                    let fj = (0..4).find(|&k| !ti.contains(&tj[k])).unwrap();
                    b.cells[i].n[fi] = (j * 4 + fj) as u32;
                }
            }
        }
        b
    }

    /// The tetrahedra, their neighbours and the free (dead) slots; scratch is dropped.
    pub fn into_parts(self) -> (Vec<Cell>, Vec<u32>) {
        (self.cells, self.free)
    }

    #[inline(always)]
    fn p(&self, v: u32) -> &Point {
        &self.pts[v as usize]
    }

    #[inline(always)]
    fn next_rand(&mut self) -> u32 {
        // xorshift32
        let mut x = self.rng;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.rng = x;
        x
    }

    /// Is tetrahedron `t` in conflict with `q` (perturbed circumsphere contains `q`)?
    #[inline(always)]
    fn in_conflict(&self, t: u32, q: &Point) -> bool {
        let v = self.cells[t as usize].v;
        if v[3] == INFINITE {
            in_conflict_infinite(self.p(v[0]), self.p(v[1]), self.p(v[2]), q, self.far)
        } else {
            in_conflict_finite([self.p(v[0]), self.p(v[1]), self.p(v[2]), self.p(v[3])], q)
        }
    }

    /// Remembering stochastic visibility walk from `start` to a tetrahedron in conflict
    /// with `q`: either a finite one containing `q` (closed) or an infinite one whose
    /// hull facet has `q` strictly on its outer side. Terminates because visibility
    /// walks are acyclic in (perturbed) Delaunay triangulations (Edelsbrunner 1990).
    fn locate(&mut self, q: &Point, start: u32) -> Result<u32, u32> {
        let mut t = start;
        let v = self.cells[t as usize].v;
        if v[3] == INFINITE {
            if orient(self.p(v[0]), self.p(v[1]), self.p(v[2]), q) > 0 {
                return Ok(t);
            }
            t = self.cells[t as usize].n[3] >> 2;
        }
        let mut prev = NONE;
        loop {
            let r = self.next_rand() as usize;
            let v = self.cells[t as usize].v;
            let pts = self.pts;
            let pv = [0, 1, 2, 3].map(|k| &pts[v[k] as usize]);
            let mut next = NONE;
            for k in 0..4 {
                let i = (r + k) & 3;
                let n = self.cells[t as usize].n[i] >> 2;
                if n == prev {
                    continue;
                }
                let mut w = pv;
                w[i] = q;
                if orient(w[0], w[1], w[2], w[3]) < 0 {
                    next = n;
                    break;
                }
            }
            if next == NONE {
                for (k, pk) in pv.iter().enumerate() {
                    if *pk == q {
                        return Err(v[k]);
                    }
                }
                return Ok(t);
            }
            prev = t;
            t = next;
            if self.cells[t as usize].v[3] == INFINITE {
                return Ok(t);
            }
        }
    }

    fn alloc(&mut self) -> u32 {
        if let Some(t) = self.free.pop() {
            t
        } else {
            let t = self.cells.len() as u32;
            self.cells.push(Cell { v: [NONE; 4], n: [NONE; 4] });
            self.mark.push(0);
            t
        }
    }

    /// Insert vertex `vid` (Bowyer–Watson): locate, grow the conflict cavity by
    /// depth-first search, and star it from the new point.
    ///
    /// # Errors
    /// [`DelaunayError::TooManyTets`] when ids would exceed 30 bits.
    pub fn insert(&mut self, vid: u32, num_inserted: usize) -> Result<Inserted, DelaunayError> {
        let q = *self.p(vid);
        let t0 = match self.locate(&q, self.last) {
            Ok(t) => t,
            Err(v) => return Ok(Inserted::Duplicate(v)),
        };
        if self.stamp >= u32::MAX - 4 {
            self.mark.iter_mut().for_each(|m| *m = 0);
            self.stamp = 0;
        }
        self.stamp += 2;
        let in_c = self.stamp;
        let out_c = self.stamp + 1;
        self.cavity.clear();
        self.boundary.clear();
        self.stack.clear();
        self.mark[t0 as usize] = in_c;
        self.cavity.push(t0);
        self.stack.push(t0);
        while let Some(t) = self.stack.pop() {
            for i in 0..4 {
                let ne = self.cells[t as usize].n[i];
                let n = ne >> 2;
                let m = self.mark[n as usize];
                if m == in_c {
                    continue;
                }
                if m != out_c {
                    if self.in_conflict(n, &q) {
                        self.mark[n as usize] = in_c;
                        self.cavity.push(n);
                        self.stack.push(n);
                        continue;
                    }
                    self.mark[n as usize] = out_c;
                }
                let mut verts = self.cells[t as usize].v;
                verts[i] = vid;
                self.boundary.push(BoundaryFacet { verts, face: i as u32, outer: ne });
            }
        }
        let grow = self.boundary.len().saturating_sub(self.cavity.len());
        if self.cells.len() - self.free.len() + grow > MAX_TETS {
            return Err(DelaunayError::TooManyTets { max_tets: MAX_TETS, num_inserted });
        }
        self.free.extend_from_slice(&self.cavity);

        // Each new tetrahedron's three faces through the new point are glued through a
        // hash table keyed by the facet's edge opposite the new point: every such edge of
        // the (sphere-like) cavity boundary is shared by exactly two boundary facets.
        let needed = (self.boundary.len() * 4).next_power_of_two().max(256);
        if self.table.len() < needed {
            self.table = vec![EdgeSlot::default(); needed];
            self.table_stamp = 0;
        }
        if self.table_stamp == u32::MAX {
            self.table.iter_mut().for_each(|s| s.stamp = 0);
            self.table_stamp = 0;
        }
        self.table_stamp += 1;
        let ts = self.table_stamp;
        let mask = self.table.len() - 1;
        let shift = 64 - self.table.len().trailing_zeros();
        let mut last_finite = NONE;
        let mut last_any = NONE;
        for bi in 0..self.boundary.len() {
            let bf = self.boundary[bi];
            let nt = self.alloc();
            let f = bf.face as usize;
            self.cells[nt as usize].v = bf.verts;
            self.cells[nt as usize].n[f] = bf.outer;
            self.cells[(bf.outer >> 2) as usize].n[(bf.outer & 3) as usize] = nt * 4 + bf.face;
            #[allow(clippy::needless_range_loop)] // j indexes OTHER and the cell
            for j in 0..4 {
                if j == f {
                    continue;
                }
                let (ia, ib) = OTHER[f][j];
                let (a, b) = (bf.verts[ia], bf.verts[ib]);
                let key = if a < b { ((a as u64) << 32) | b as u64 } else { ((b as u64) << 32) | a as u64 };
                let mut h = (key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> shift) as usize & mask;
                let code = nt * 4 + j as u32;
                loop {
                    let slot = &mut self.table[h];
                    if slot.stamp != ts {
                        *slot = EdgeSlot { key, value: code, stamp: ts };
                        break;
                    }
                    if slot.key == key {
                        let other = slot.value;
                        // Invalidate the key so a (never expected) third use cannot
                        // match it again.
                        slot.key = u64::MAX;
                        self.cells[nt as usize].n[j] = other;
                        self.cells[(other >> 2) as usize].n[(other & 3) as usize] = code;
                        break;
                    }
                    h = (h + 1) & mask;
                }
            }
            last_any = nt;
            if bf.verts[3] != INFINITE {
                last_finite = nt;
            }
        }
        self.last = if last_finite != NONE { last_finite } else { last_any };
        Ok(Inserted::New)
    }
}
