//! The entry type [`Delaunay3`]: construction and topology accessors.

use crate::build::{Builder, Cell, Inserted, INFINITE};
use crate::error::DelaunayError;
use crate::normalize::{normalize, scale_pow2};
use crate::predicates::{orient, Point};
use crate::spatial_sort::{brio_hilbert_sort, Item};

/// Most input points accepted (vertex ids are u32 and tetrahedron ids 30-bit; a
/// uniform set of n points has about 6.8 n tetrahedra including infinite ones).
pub const MAX_POINTS: usize = 100_000_000;

/// An exact 3D Delaunay tetrahedralization.
///
/// Built by incremental Bowyer–Watson insertion (Bowyer 1981; Watson 1981) in BRIO order
/// along a Hilbert curve (Amenta, Choi & Rote 2003), with point location by a
/// remembering stochastic walk (Devillers, Pion & Teillaud 2002), Shewchuk's adaptive
/// exact predicates (Shewchuk 1997) behind a stage-A floating-point filter, and symbolic
/// perturbation of the lifted coordinate (Edelsbrunner & Mücke 1990; Devillers &
/// Teillaud 2011) for cospherical and coplanar degeneracies. The result is *the*
/// Delaunay tetrahedralization of the perturbed points — a valid Delaunay
/// tetrahedralization of the input (every circumsphere empty of points in its interior)
/// that does not depend on the input order.
///
/// Storage: tetrahedra are `[u32; 4]` vertex ids; ids `0..num_finite_tets()` are the
/// finite tetrahedra, the rest are infinite (vertex 3 is [`INFINITE`], the other three a
/// convex-hull facet). Every tetrahedron is positively oriented:
/// `det[b − a, c − a, d − a] > 0` for finite `[a, b, c, d]`; an infinite one has the
/// hull on the negative side of its facet. Neighbour `i` of a tetrahedron is across
/// the facet opposite its vertex `i`; every facet has a tetrahedron on each side.
///
/// Vertex ids `0..num_vertices()` index the deduplicated points in the spatially sorted
/// insertion order (so that vertex data downstream enjoys memory locality); map them
/// with [`Self::input_of_vertex`] (the first input index holding the point) and
/// [`Self::vertex_of_input`].
#[derive(Debug, Clone)]
pub struct Delaunay3 {
    /// #V×3 f64: vertex coordinates times `2^scale_exp` (exact), the frame the
    /// predicates run in.
    pub(crate) points: Vec<Point>,
    pub(crate) scale_exp: i32,
    pub(crate) far: f64,
    /// #T tetrahedra (vertex ids and neighbours encoded `tet * 4 + face_in_neighbour`),
    /// finite first, ordered along the vertices' spatial order.
    pub(crate) cells: Vec<Cell>,
    pub(crate) num_finite: usize,
    pub(crate) vertex_of_input: Vec<u32>,
    pub(crate) input_of_vertex: Vec<u32>,
}

impl Delaunay3 {
    /// Delaunay tetrahedralization of `points`.
    ///
    /// `points`: #N×3 f64, any units and frame; every coordinate finite, and the
    /// nonzero |coordinates| within a ratio of about 2^300 of each other
    /// ([`crate::normalize::SafeRange`]); absolute magnitude is free (the input is
    /// rescaled exactly by a power of two). Coincident points are merged
    /// ([`Self::vertex_of_input`]).
    ///
    /// # Complexity
    /// Expected O(n log n) time for well-distributed points (the sort; insertion is
    /// expected linear in BRIO order), O(n²) worst case (the output size). For uniform
    /// inputs about 6.75 tetrahedra per point: the result keeps about 250 bytes per
    /// point, construction peaks at about 500.
    ///
    /// # Errors
    /// [`DelaunayError::NonFinite`] for NaN/infinite coordinates,
    /// [`DelaunayError::RangeTooWide`] when the coordinates cannot be brought into the
    /// safe range, [`DelaunayError::Degenerate`] when the points do not span 3D,
    /// [`DelaunayError::TooManyPoints`] / [`DelaunayError::TooManyTets`] beyond the id
    /// range.
    ///
    /// # Example
    /// ```
    /// # fn main() -> Result<(), delaunay3::DelaunayError> {
    /// let cube: Vec<[f64; 3]> = (0..8)
    ///     .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, (i >> 2) as f64])
    ///     .collect();
    /// let dt = delaunay3::Delaunay3::new(&cube)?;
    /// dt.validate().expect("valid");
    /// assert_eq!(dt.num_vertices(), 8);
    /// // A cube has 8 cospherical corners; the perturbation picks one triangulation.
    /// assert!(dt.num_finite_tets() == 5 || dt.num_finite_tets() == 6);
    /// # Ok(())
    /// # }
    /// ```
    pub fn new(points: &[[f64; 3]]) -> Result<Self, DelaunayError> {
        let n = points.len();
        if n > MAX_POINTS {
            return Err(DelaunayError::TooManyPoints { num_points: n, max_points: MAX_POINTS });
        }
        let norm = normalize(points)?;
        let mut items: Vec<Item> =
            norm.points.iter().enumerate().map(|(i, p)| Item { p: *p, index: i as u32 }).collect();
        drop(norm.points);
        brio_hilbert_sort(&mut items);
        // Internal vertex ids are positions in the insertion order, for memory locality.
        let pts: Vec<Point> = items.iter().map(|it| it.p).collect();
        let order: Vec<u32> = items.iter().map(|it| it.index).collect();
        drop(items);

        let init = initial_simplex(&pts)?;
        let mut builder = Builder::new(&pts, norm.far, init);
        let mut dup_of = vec![u32::MAX; n];
        let mut inserted = 4usize;
        for v in 0..n as u32 {
            if init.contains(&v) {
                continue;
            }
            match builder.insert(v, inserted)? {
                Inserted::New => inserted += 1,
                Inserted::Duplicate(w) => dup_of[v as usize] = w,
            }
        }

        // Final vertex ids: the inserted points in insertion order (spatially sorted, for
        // memory locality downstream); duplicates are dropped from the id space.
        let num_dups = n - inserted;
        let mut final_id: Vec<u32> = Vec::new();
        if num_dups > 0 {
            final_id = vec![u32::MAX; n];
            let mut next = 0u32;
            for k in 0..n {
                if dup_of[k] == u32::MAX {
                    final_id[k] = next;
                    next += 1;
                }
            }
        }
        let fid = |k: usize| if num_dups > 0 { final_id[k] } else { k as u32 };
        let (cells, num_finite) = compact(builder, fid, inserted);
        let mut points_out = pts;
        if num_dups > 0 {
            for k in 0..n {
                if final_id[k] != u32::MAX {
                    points_out[final_id[k] as usize] = points_out[k];
                }
            }
            points_out.truncate(inserted);
            points_out.shrink_to_fit();
        }
        // Representative: the first input index holding the point.
        let mut vertex_of_input = vec![0u32; n];
        for (k, &i) in order.iter().enumerate() {
            let c = if dup_of[k] != u32::MAX { dup_of[k] as usize } else { k };
            vertex_of_input[i as usize] = fid(c);
        }
        let mut input_of_vertex = vec![u32::MAX; inserted];
        for (i, &v) in vertex_of_input.iter().enumerate() {
            if input_of_vertex[v as usize] == u32::MAX {
                input_of_vertex[v as usize] = i as u32;
            }
        }
        Ok(Delaunay3 {
            points: points_out,
            scale_exp: norm.scale_exp,
            far: norm.far,
            cells,
            num_finite,
            vertex_of_input,
            input_of_vertex,
        })
    }

    /// Number of input points given to [`Self::new`].
    pub fn num_inputs(&self) -> usize {
        self.vertex_of_input.len()
    }

    /// Number of distinct vertices (input points after merging duplicates).
    pub fn num_vertices(&self) -> usize {
        self.points.len()
    }

    /// Number of finite tetrahedra.
    pub fn num_finite_tets(&self) -> usize {
        self.num_finite
    }

    /// Number of tetrahedra including the infinite ones (one per convex-hull facet).
    pub fn num_tets(&self) -> usize {
        self.cells.len()
    }

    /// Finite tetrahedra: #M×4 u32 vertex ids, positively oriented
    /// (`det[b − a, c − a, d − a] > 0`). Their tetrahedron ids are `0..M`.
    pub fn finite_tets(&self) -> impl ExactSizeIterator<Item = [u32; 4]> + '_ {
        self.cells[..self.num_finite].iter().map(|c| c.v)
    }

    /// All tetrahedra, #T×4 u32 vertex ids: `0..num_finite_tets()` finite, the rest
    /// infinite with vertex 3 equal to [`INFINITE`].
    pub fn tets(&self) -> impl ExactSizeIterator<Item = [u32; 4]> + '_ {
        self.cells.iter().map(|c| c.v)
    }

    /// The infinite tetrahedra (one per convex-hull facet), #H×4 u32, vertex 3 is
    /// [`INFINITE`] and `[0, 1, 2]` is the hull facet, counter-clockwise seen from
    /// outside.
    pub fn infinite_tets(&self) -> impl ExactSizeIterator<Item = [u32; 4]> + '_ {
        self.cells[self.num_finite..].iter().map(|c| c.v)
    }

    /// Vertex ids of tetrahedron `t`.
    ///
    /// # Panics
    /// If `t >= num_tets()`.
    pub fn tet(&self, t: u32) -> [u32; 4] {
        self.cells[t as usize].v
    }

    /// Whether tetrahedron `t` has the infinite vertex.
    pub fn is_infinite(&self, t: u32) -> bool {
        t as usize >= self.num_finite
    }

    /// The tetrahedron across face `i` of `t` (the facet opposite vertex `i`) and that
    /// facet's index in it.
    ///
    /// # Panics
    /// If `t >= num_tets()` or `i >= 4`.
    pub fn neighbor(&self, t: u32, i: usize) -> (u32, usize) {
        let e = self.cells[t as usize].n[i];
        (e >> 2, (e & 3) as usize)
    }

    /// The four neighbouring tetrahedron ids of `t`, by face.
    pub fn neighbors(&self, t: u32) -> [u32; 4] {
        self.cells[t as usize].n.map(|e| e >> 2)
    }

    /// The vertex representing input point `i` (duplicates share it).
    ///
    /// # Panics
    /// If `i >= num_inputs()`.
    pub fn vertex_of_input(&self, i: usize) -> u32 {
        self.vertex_of_input[i]
    }

    /// #N u32: the vertex of every input point.
    pub fn vertex_of_input_map(&self) -> &[u32] {
        &self.vertex_of_input
    }

    /// The first input index holding vertex `v`.
    ///
    /// # Panics
    /// If `v >= num_vertices()`.
    pub fn input_of_vertex(&self, v: u32) -> u32 {
        self.input_of_vertex[v as usize]
    }

    /// #V u32: the representative (first) input index of every vertex.
    pub fn input_of_vertex_map(&self) -> &[u32] {
        &self.input_of_vertex
    }

    /// Coordinates of vertex `v`, exactly as given (except that −0.0 reads as 0.0).
    ///
    /// # Panics
    /// If `v` is not a finite vertex id.
    pub fn vertex(&self, v: u32) -> [f64; 3] {
        let p = self.points[v as usize];
        if self.scale_exp == 0 {
            p
        } else {
            p.map(|x| scale_pow2(x, -self.scale_exp))
        }
    }

    /// The exponent `k` of the exact internal scaling `2^k` (0 when the input was
    /// already in the safe range).
    pub fn scale_exponent(&self) -> i32 {
        self.scale_exp
    }

    /// Finite tetrahedra with vertex ids mapped back to input indices: #M×4 u32, each a
    /// representative input index ([`Self::input_of_vertex`]), positively oriented.
    pub fn finite_tets_input_indices(&self) -> Vec<[u32; 4]> {
        self.finite_tets().map(|t| t.map(|v| self.input_of_vertex[v as usize])).collect()
    }

    /// Exact orientation sign of four vertices (internal frame; same sign as the input).
    pub(crate) fn orient_v(&self, t: [u32; 4]) -> i32 {
        let p = |v: u32| &self.points[v as usize];
        orient(p(t[0]), p(t[1]), p(t[2]), p(t[3]))
    }
}

/// Four affinely independent vertex ids (positions in insertion order), the first such
/// found scanning in order.
fn initial_simplex(pts: &[Point]) -> Result<[u32; 4], DelaunayError> {
    let n = pts.len();
    let degenerate = |num_distinct: usize, dimension: i32, shape: &'static str| {
        Err(DelaunayError::Degenerate { num_points: n, num_distinct, dimension, shape })
    };
    if n == 0 {
        return degenerate(0, -1, "are none");
    }
    let Some(i1) = (1..n).find(|&i| pts[i] != pts[0]) else {
        return degenerate(1, 0, "all coincide");
    };
    let (a, b) = (pts[0], pts[i1]);
    let Some(i2) = (i1 + 1..n).find(|&i| !collinear(&a, &b, &pts[i])) else {
        return degenerate(2, 1, "are collinear");
    };
    let c = pts[i2];
    let Some(i3) = (i2 + 1..n).find(|&i| orient(&a, &b, &c, &pts[i]) != 0) else {
        return degenerate(3, 2, "are coplanar");
    };
    Ok([0, i1 as u32, i2 as u32, i3 as u32])
}

/// Exact collinearity: all three coordinate-plane projections have zero orientation.
fn collinear(a: &Point, b: &Point, c: &Point) -> bool {
    use robust::{orient2d, Coord};
    let proj = |p: &Point, i: usize, j: usize| Coord { x: p[i], y: p[j] };
    [(0, 1), (1, 2), (2, 0)].iter().all(|&(i, j)| orient2d(proj(a, i, j), proj(b, i, j), proj(c, i, j)) == 0.0)
}

/// Drop dead slots and order the tetrahedra finite first, each part sorted by its
/// largest vertex id (vertex ids follow the Hilbert insertion order, so neighbouring
/// tetrahedra end up close in memory), renumbering vertices with `fid`. A counting sort
/// computes the new ids; contents are renumbered in place, then scattered to a new array. Returns `(cells, num_finite)`.
fn compact(builder: Builder<'_>, fid: impl Fn(usize) -> u32, num_vertices: usize) -> (Vec<Cell>, usize) {
    let (mut cells, free) = builder.into_parts();
    const DEAD: u32 = u32::MAX;
    let len = cells.len();
    // Bucket of each slot: 0..nv for finite (largest vertex), nv for infinite, DEAD.
    let mut new_id = vec![0u32; len];
    for (t, c) in cells.iter().enumerate() {
        new_id[t] =
            if c.v[3] == INFINITE { num_vertices as u32 } else { fid(c.v.iter().copied().max().unwrap_or(0) as usize) };
    }
    for &t in &free {
        new_id[t as usize] = DEAD;
    }
    drop(free);
    let mut start = vec![0u32; num_vertices + 2];
    for &b in &new_id {
        if b != DEAD {
            start[b as usize + 1] += 1;
        }
    }
    for b in 0..=num_vertices {
        start[b + 1] += start[b];
    }
    let num_finite = start[num_vertices] as usize;
    let num_live = start[num_vertices + 1] as usize;
    let mut next_dead = num_live as u32;
    for b in new_id.iter_mut() {
        if *b == DEAD {
            *b = next_dead;
            next_dead += 1;
        } else {
            let slot = &mut start[*b as usize];
            let id = *slot;
            *slot += 1;
            *b = id;
        }
    }
    drop(start);
    for (t, c) in cells.iter_mut().enumerate() {
        if new_id[t] as usize >= num_live {
            continue;
        }
        c.v = c.v.map(|x| if x == INFINITE { x } else { fid(x as usize) });
        c.n = c.n.map(|e| (new_id[(e >> 2) as usize] << 2) | (e & 3));
    }
    let mut out = vec![Cell { v: [0; 4], n: [0; 4] }; num_live];
    for (t, c) in cells.iter().enumerate() {
        let id = new_id[t] as usize;
        if id < num_live {
            out[id] = *c;
        }
    }
    (out, num_finite)
}
