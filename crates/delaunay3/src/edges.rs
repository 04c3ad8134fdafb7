//! Edges of the tetrahedralization: the Delaunay edge graph, vertex stars and the ring
//! of tetrahedra around an edge (what the crust and the centroidal loss need).

use crate::build::INFINITE;
use crate::triangulation::Delaunay3;

/// A finite Delaunay edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Edge {
    /// The two vertex ids, `vertices[0] < vertices[1]`.
    pub vertices: [u32; 2],
    /// A finite tetrahedron containing the edge (start for [`Delaunay3::tets_around_edge`]).
    pub tet: u32,
}

/// The finite tetrahedra incident to each vertex, in compressed rows.
#[derive(Debug, Clone)]
pub struct VertexTets {
    /// #V+1 u32: row `v` is `tets[offsets[v]..offsets[v+1]]`.
    pub offsets: Vec<u32>,
    /// #(4M) u32: finite tetrahedron ids, increasing within a row.
    pub tets: Vec<u32>,
}

impl VertexTets {
    /// The finite tetrahedra incident to vertex `v`.
    pub fn of(&self, v: u32) -> &[u32] {
        &self.tets[self.offsets[v as usize] as usize..self.offsets[v as usize + 1] as usize]
    }
}

impl Delaunay3 {
    /// The finite tetrahedra around every vertex.
    ///
    /// # Complexity
    /// O(M) time and memory (counting sort), M the number of finite tetrahedra.
    pub fn vertex_tets(&self) -> VertexTets {
        let nv = self.points.len();
        let mut offsets = vec![0u32; nv + 1];
        for t in self.finite_tets() {
            for v in t {
                offsets[v as usize + 1] += 1;
            }
        }
        for v in 0..nv {
            offsets[v + 1] += offsets[v];
        }
        let mut fill = offsets.clone();
        let mut tets = vec![0u32; self.num_finite * 4];
        for (t, verts) in self.finite_tets().enumerate() {
            for v in verts {
                let slot = &mut fill[v as usize];
                tets[*slot as usize] = t as u32;
                *slot += 1;
            }
        }
        VertexTets { offsets, tets }
    }

    /// Every finite Delaunay edge once, sorted by `(vertices[0], vertices[1])`, with a
    /// finite tetrahedron containing it.
    ///
    /// # Complexity
    /// O(M) time (M finite tetrahedra), about 1.1 edges per tetrahedron.
    pub fn edges(&self) -> Vec<Edge> {
        let stars = self.vertex_tets();
        let nv = self.points.len();
        let mut seen = vec![u32::MAX; nv];
        let mut edges = Vec::with_capacity(self.num_finite * 6 / 5 + 16);
        for a in 0..nv as u32 {
            let start = edges.len();
            for &t in stars.of(a) {
                for w in self.cells[t as usize].v {
                    if w > a && seen[w as usize] != a {
                        seen[w as usize] = a;
                        edges.push(Edge { vertices: [a, w], tet: t });
                    }
                }
            }
            edges[start..].sort_unstable_by_key(|e| e.vertices[1]);
        }
        edges
    }

    /// The ring of tetrahedra (finite and infinite) around edge `(a, b)`, starting with
    /// `tet`, in the positive rotation sense about the direction `a → b`; written to
    /// `out` (cleared first). Consecutive tetrahedra share a facet containing the edge;
    /// for an edge on the convex hull the ring contains infinite tetrahedra. The Voronoi
    /// face dual to the edge has the circumcentres of the finite ring members as corners,
    /// in this order.
    ///
    /// # Complexity
    /// O(ring length).
    ///
    /// # Panics
    /// If `tet` does not contain both `a` and `b`, or `a == b`.
    pub fn tets_around_edge(&self, tet: u32, a: u32, b: u32, out: &mut Vec<u32>) {
        out.clear();
        let v = self.cells[tet as usize].v;
        let ia = v.iter().position(|&x| x == a).expect("tet contains a");
        let ib = v.iter().position(|&x| x == b).expect("tet contains b");
        assert_ne!(ia, ib, "edge endpoints must differ");
        let mut rest = (0..4).filter(|&k| k != ia && k != ib);
        let (mut ic, mut id) = (rest.next().unwrap(), rest.next().unwrap());
        if !is_even([ia, ib, ic, id]) {
            std::mem::swap(&mut ic, &mut id);
        }
        let (mut t, mut c, mut d) = (tet, v[ic], v[id]);
        loop {
            out.push(t);
            let vt = self.cells[t as usize].v;
            let ic = vt.iter().position(|&x| x == c).unwrap();
            let n = self.cells[t as usize].n[ic] >> 2;
            if n == tet {
                break;
            }
            let vn = self.cells[n as usize].v;
            let e = *vn.iter().find(|&&x| x != a && x != b && x != d).unwrap();
            t = n;
            c = d;
            d = e;
        }
        debug_assert!(out.iter().all(|&t| {
            let v = self.cells[t as usize].v;
            v.contains(&a) && v.contains(&b)
        }));
    }

    /// Whether vertex id `v` is the infinite vertex.
    pub fn is_infinite_vertex(v: u32) -> bool {
        v == INFINITE
    }
}

/// Parity of a permutation of 0..4.
fn is_even(p: [usize; 4]) -> bool {
    let mut inversions = 0;
    for i in 0..4 {
        for j in i + 1..4 {
            if p[i] > p[j] {
                inversions += 1;
            }
        }
    }
    inversions % 2 == 0
}
