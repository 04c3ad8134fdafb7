//! Outside by flood fill, for soups whose winding number is not decisive (single-sided
//! panels, open or flipped boxes, doubled or buried faces): a regular grid of cells over
//! the mesh's box, where a cell whose centre lies within the wall radius of a triangle is a
//! wall and every cell reached from the grid's border through non-wall cells (6-connected)
//! is outside; the rest is enclosed. Gaps narrower than about two wall radii plus a cell are
//! closed; any closed surface, whatever its triangles' orientation, doubled or intersecting,
//! keeps the flood out (a path between two face-adjacent cell centres that crosses the
//! surface passes within half a cell of one of them, and the wall radius is more).
//!
//! The grid answers for cells; [`FloodGrid::side`] answers for one side of a surface point
//! by stepping off it along a direction until a non-wall cell, which lets a solid built on
//! it put its boundary on the input's surface rather than a wall radius away (the
//! voxelising converters' offset).
//!
//! Written here rather than taken from a crate: the flood is a breadth-first search over a
//! byte grid and the walls a rasterisation by the crate's exact point-triangle distance;
//! the voxel crates on crates.io voxelise by triangle-box overlap without a radius, or
//! bring a renderer.

use std::collections::VecDeque;

use rayon::prelude::*;
use vf_common::vec3::{norm_squared, sub, V3};

use crate::distance::closest_point_triangle::closest_point_triangle;
use crate::error::OccupancyError;

/// Largest number of cells a grid may have (one byte each).
pub const MAX_CELLS: usize = 1 << 27;

/// What a cell of a [`FloodGrid`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cell {
    /// Reached from the border without crossing a wall (or beyond the grid).
    Outside,
    /// Not reached: enclosed by walls.
    Enclosed,
    /// Its centre lies within the wall radius of the surface.
    Wall,
}

const ENCLOSED: u8 = 0;
const OUTSIDE: u8 = 1;
const WALL: u8 = 2;

/// The flood-filled grid (module doc).
#[derive(Clone, Debug)]
pub struct FloodGrid {
    lo: V3,
    cell: f64,
    dims: [usize; 3],
    labels: Vec<u8>,
    wall_radius: f64,
}

/// Counts of a grid's cells by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CellCounts {
    /// Outside cells.
    pub outside: usize,
    /// Enclosed cells.
    pub enclosed: usize,
    /// Wall cells.
    pub wall: usize,
}

impl FloodGrid {
    /// Builds the grid over the box of `positions` (referenced by `triangles`) with cubic
    /// cells of side `cell`, padded by the wall radius and two cells so the border is never
    /// a wall; the wall radius is half the cell's diagonal (√3/2 · `cell`), so a non-wall
    /// cell holds no surface at all.
    ///
    /// # Errors
    /// [`OccupancyError::BadSampler`] for a non-positive or non-finite cell, no triangles,
    /// an index out of range, or more than [`MAX_CELLS`] cells.
    pub fn build(positions: &[V3], triangles: &[[u32; 3]], cell: f64) -> Result<Self, OccupancyError> {
        let bad = |m: String| Err(OccupancyError::BadSampler(m));
        if !(cell.is_finite() && cell > 0.0) {
            return bad(format!("flood fill: the cell size must be finite and > 0, got {cell}"));
        }
        if triangles.is_empty() {
            return bad("flood fill: the mesh has no triangles".into());
        }
        let mut corners = Vec::with_capacity(triangles.len());
        for (t, tri) in triangles.iter().enumerate() {
            let mut c = [[0.0; 3]; 3];
            for (k, &v) in tri.iter().enumerate() {
                match positions.get(v as usize) {
                    Some(p) if p.iter().all(|x| x.is_finite()) => c[k] = *p,
                    _ => return bad(format!("flood fill: triangle {t} has a missing or non-finite vertex {v}")),
                }
            }
            corners.push(c);
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for c in &corners {
            for p in c {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
        }
        let wall_radius = 0.5 * 3f64.sqrt() * cell;
        let pad = wall_radius + 2.0 * cell;
        let mut dims = [0usize; 3];
        for k in 0..3 {
            lo[k] -= pad;
            let n = ((hi[k] + pad - lo[k]) / cell).ceil();
            if !(n.is_finite() && n <= MAX_CELLS as f64) {
                return bad(format!("flood fill: a cell of {cell} makes too many cells"));
            }
            dims[k] = (n as usize).max(1);
        }
        let total = dims[0].saturating_mul(dims[1]).saturating_mul(dims[2]);
        if total > MAX_CELLS {
            return bad(format!(
                "flood fill: {}×{}×{} cells is more than {MAX_CELLS}; use larger cells",
                dims[0], dims[1], dims[2]
            ));
        }
        let mut grid = FloodGrid { lo, cell, dims, labels: vec![ENCLOSED; total], wall_radius };
        let walls: Vec<Vec<u32>> = corners.par_chunks(256).map(|chunk| grid.wall_cells(chunk)).collect();
        for w in walls {
            for i in w {
                grid.labels[i as usize] = WALL;
            }
        }
        grid.flood();
        Ok(grid)
    }

    /// Cells whose centre lies within the wall radius of one of `triangles`: each triangle
    /// is split in four until its box spans at most four cells, then the cells of the
    /// padded box are tested by exact point-triangle distance.
    fn wall_cells(&self, triangles: &[[V3; 3]]) -> Vec<u32> {
        let mut out = Vec::new();
        let mut stack: Vec<[V3; 3]> = Vec::new();
        let r2 = self.wall_radius * self.wall_radius;
        for t in triangles {
            stack.push(*t);
            while let Some([a, b, c]) = stack.pop() {
                let lo: V3 = [0, 1, 2].map(|k| a[k].min(b[k]).min(c[k]));
                let hi: V3 = [0, 1, 2].map(|k| a[k].max(b[k]).max(c[k]));
                if (0..3).any(|k| hi[k] - lo[k] > 4.0 * self.cell) {
                    let mid = |p: V3, q: V3| [0, 1, 2].map(|k| 0.5 * (p[k] + q[k]));
                    let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
                    stack.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
                    continue;
                }
                let range = |k: usize| {
                    let from = ((lo[k] - self.wall_radius - self.lo[k]) / self.cell - 0.5).floor().max(0.0) as usize;
                    let to = (((hi[k] + self.wall_radius - self.lo[k]) / self.cell - 0.5).ceil().max(0.0) as usize)
                        .min(self.dims[k] - 1);
                    from..=to
                };
                for i in range(0) {
                    for j in range(1) {
                        for l in range(2) {
                            let p = self.center([i, j, l]);
                            if norm_squared(sub(p, closest_point_triangle(p, a, b, c))) <= r2 {
                                out.push(self.index([i, j, l]) as u32);
                            }
                        }
                    }
                }
            }
        }
        out
    }

    /// Breadth-first flood from every non-wall border cell through face neighbours.
    fn flood(&mut self) {
        let [nx, ny, nz] = self.dims;
        let mut queue = VecDeque::new();
        for i in 0..nx {
            for j in 0..ny {
                for l in 0..nz {
                    let border = i == 0 || j == 0 || l == 0 || i == nx - 1 || j == ny - 1 || l == nz - 1;
                    let at = self.index([i, j, l]);
                    if border && self.labels[at] == ENCLOSED {
                        self.labels[at] = OUTSIDE;
                        queue.push_back([i, j, l]);
                    }
                }
            }
        }
        while let Some(c) = queue.pop_front() {
            for (k, d) in [(0, -1i64), (0, 1), (1, -1), (1, 1), (2, -1), (2, 1)] {
                let v = c[k] as i64 + d;
                if v < 0 || v >= self.dims[k] as i64 {
                    continue;
                }
                let mut n = c;
                n[k] = v as usize;
                let at = self.index(n);
                if self.labels[at] == ENCLOSED {
                    self.labels[at] = OUTSIDE;
                    queue.push_back(n);
                }
            }
        }
    }

    fn index(&self, [i, j, l]: [usize; 3]) -> usize {
        (i * self.dims[1] + j) * self.dims[2] + l
    }

    fn center(&self, c: [usize; 3]) -> V3 {
        [0, 1, 2].map(|k| self.lo[k] + (c[k] as f64 + 0.5) * self.cell)
    }

    /// The cell holding `p`; points beyond the grid (or not finite) are outside.
    pub fn cell_at(&self, p: V3) -> Cell {
        let mut c = [0usize; 3];
        for k in 0..3 {
            let f = (p[k] - self.lo[k]) / self.cell;
            if !(f >= 0.0 && f < self.dims[k] as f64) {
                return Cell::Outside;
            }
            c[k] = f as usize;
        }
        match self.labels[self.index(c)] {
            ENCLOSED => Cell::Enclosed,
            OUTSIDE => Cell::Outside,
            _ => Cell::Wall,
        }
    }

    /// Which region lies on the `dir` side of the surface point `q`: steps of half a cell
    /// from the wall radius out to the wall radius plus three cells along the unit vector
    /// `dir`, and returns whether the first non-wall cell met is enclosed; `None` when
    /// every step is in a wall (a crevice narrower than the walls, a corner).
    pub fn side(&self, q: V3, dir: V3) -> Option<bool> {
        let mut t = self.wall_radius;
        while t <= self.wall_radius + 3.0 * self.cell {
            match self.cell_at([0, 1, 2].map(|k| q[k] + t * dir[k])) {
                Cell::Wall => t += 0.5 * self.cell,
                c => return Some(c == Cell::Enclosed),
            }
        }
        None
    }

    /// The cell side.
    pub fn cell(&self) -> f64 {
        self.cell
    }

    /// The wall radius (half the cell's diagonal).
    pub fn wall_radius(&self) -> f64 {
        self.wall_radius
    }

    /// Cells along each axis.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// How many cells of each kind.
    pub fn counts(&self) -> CellCounts {
        let mut c = CellCounts::default();
        for &l in &self.labels {
            match l {
                ENCLOSED => c.enclosed += 1,
                OUTSIDE => c.outside += 1,
                _ => c.wall += 1,
            }
        }
        c
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An axis-aligned box [lo, hi]³ as 12 triangles; `flip` turns face pairs inside out
    /// and `drop_top` leaves the top (z = hi) open.
    fn cube(lo: f64, hi: f64, flip: bool, drop_top: bool) -> (Vec<V3>, Vec<[u32; 3]>) {
        let mut p = Vec::new();
        for i in 0..8 {
            p.push([
                if i & 1 == 0 { lo } else { hi },
                if i & 2 == 0 { lo } else { hi },
                if i & 4 == 0 { lo } else { hi },
            ]);
        }
        let mut t = vec![
            [0, 2, 1],
            [1, 2, 3],
            [4, 5, 6],
            [5, 7, 6],
            [0, 1, 4],
            [1, 5, 4],
            [2, 6, 3],
            [3, 6, 7],
            [0, 4, 2],
            [2, 4, 6],
            [1, 3, 5],
            [3, 7, 5],
        ];
        if drop_top {
            t.drain(2..4);
        }
        if flip {
            for (i, tri) in t.iter_mut().enumerate() {
                if i % 3 == 0 {
                    tri.swap(1, 2);
                }
            }
        }
        (p, t)
    }

    #[test]
    fn closed_box_encloses_whatever_its_orientation() {
        for flip in [false, true] {
            let (p, t) = cube(0.2, 0.8, flip, false);
            let g = FloodGrid::build(&p, &t, 0.02).unwrap();
            assert_eq!(g.cell_at([0.5, 0.5, 0.5]), Cell::Enclosed);
            assert_eq!(g.cell_at([0.1, 0.5, 0.5]), Cell::Outside);
            assert_eq!(g.cell_at([0.2, 0.5, 0.5]), Cell::Wall);
            assert_eq!(g.cell_at([5.0, 0.5, 0.5]), Cell::Outside);
            // Each side of a face.
            assert_eq!(g.side([0.2, 0.5, 0.5], [1.0, 0.0, 0.0]), Some(true));
            assert_eq!(g.side([0.2, 0.5, 0.5], [-1.0, 0.0, 0.0]), Some(false));
            let c = g.counts();
            assert!(c.enclosed > 0 && c.outside > 0 && c.wall > 0);
        }
    }

    #[test]
    fn open_box_floods_and_small_gaps_close() {
        let (p, t) = cube(0.2, 0.8, false, true);
        let g = FloodGrid::build(&p, &t, 0.02).unwrap();
        assert_eq!(g.cell_at([0.5, 0.5, 0.5]), Cell::Outside);
        // A box whose top stands 0.01 above its walls: the gap is narrower than the walls.
        let (mut p, t) = cube(0.2, 0.8, false, false);
        for v in p.iter_mut().skip(4) {
            v[2] = 0.79;
        }
        let (mut lid, mut tl) = (p.clone(), t.clone());
        for v in lid.iter_mut().skip(4) {
            v[2] = 0.8;
        }
        // Walls up to 0.79, the lid (two triangles) at 0.8.
        tl.retain(|tri| tri.iter().all(|&v| v >= 4));
        let mut tris: Vec<[u32; 3]> = t.iter().copied().filter(|tri| !tri.iter().all(|&v| v >= 4)).collect();
        let off = p.len() as u32;
        p.extend(lid);
        tris.extend(tl.iter().map(|tri| tri.map(|v| v + off)));
        let g = FloodGrid::build(&p, &tris, 0.02).unwrap();
        assert_eq!(g.cell_at([0.5, 0.5, 0.5]), Cell::Enclosed);
    }

    #[test]
    fn refuses_bad_settings() {
        let (p, t) = cube(0.2, 0.8, false, false);
        assert!(FloodGrid::build(&p, &t, 0.0).is_err());
        assert!(FloodGrid::build(&p, &t, 1e-6).is_err());
        assert!(FloodGrid::build(&p, &[], 0.02).is_err());
        assert!(FloodGrid::build(&p, &[[0, 1, 99]], 0.02).is_err());
    }
}
