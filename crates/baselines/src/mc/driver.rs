//! The marching-cubes driver: input checks, then cell by cell the corner values, the
//! welded vertices of the crossed edges, the polygons chained from the face segments, and
//! their triangles (classic table, fans or a tube).

use std::collections::HashMap;

use mesh_io::TriMesh;
use ndarray::ArrayView3;

use super::ambiguity::{face_segments, joined_inside};
use super::classic::classic_triangles;
use super::cube::{corner_face_mask, edge_face_mask, edge_lower_corner};
use super::polygons::{triangulate, tube_triangles};
use super::{Ambiguity, Inside, McOptions};
use crate::error::{config_err, BaselineError, Result};

/// The level set of `grid` as a welded triangle mesh (see the module documentation).
///
/// Errors: a grid smaller than 2 along an axis, a non-finite value, level, origin or
/// spacing, or a non-positive spacing. An empty mesh (no crossing) is not an error.
pub fn marching_cubes(grid: ArrayView3<f64>, opts: &McOptions) -> Result<TriMesh> {
    check_inputs(&grid, opts)?;
    let (nx, ny, nz) = grid.dim();
    let mut mesher = Mesher::new(grid, opts);
    for i in 0..nx - 1 {
        for j in 0..ny - 1 {
            for k in 0..nz - 1 {
                mesher.cell([i, j, k]);
            }
        }
    }
    Ok(TriMesh { positions: mesher.positions, triangles: mesher.triangles })
}

/// The errors of [`marching_cubes()`].
fn check_inputs(grid: &ArrayView3<f64>, opts: &McOptions) -> Result<()> {
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
    Ok(())
}

/// The mesh being built, the weld map, and per-cell scratch space (reused, no allocation
/// per cell).
struct Mesher<'g, 'o> {
    grid: ArrayView3<'g, f64>,
    opts: &'o McOptions,
    positions: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    /// Vertex of each crossed grid edge (key: axis · points + point) or grid point exactly
    /// on the level (key: 3 · points + point).
    vertex_of: HashMap<u64, u32>,
    /// Strides of the point key along axes 0 and 1.
    strides: (u64, u64),
    n_points: u64,
    /// Corner values minus the level.
    v: [f64; 8],
    /// Vertex of each local edge (`u32::MAX` if not crossed).
    local_vertex: [u32; 12],
    /// Faces of the cell each local vertex lies on.
    local_faces: [u8; 12],
    edge_faces: [u8; 12],
    cycles: [Vec<(u32, u8)>; 6],
    fan: Vec<[u32; 3]>,
    tri_buf: Vec<[u32; 3]>,
}

impl<'g, 'o> Mesher<'g, 'o> {
    fn new(grid: ArrayView3<'g, f64>, opts: &'o McOptions) -> Self {
        let (nx, ny, nz) = grid.dim();
        Mesher {
            grid,
            opts,
            positions: Vec::new(),
            triangles: Vec::new(),
            vertex_of: HashMap::new(),
            strides: ((ny * nz) as u64, nz as u64),
            n_points: (nx * ny * nz) as u64,
            v: [0.0; 8],
            local_vertex: [u32::MAX; 12],
            local_faces: [0; 12],
            edge_faces: std::array::from_fn(edge_face_mask),
            cycles: std::array::from_fn(|_| Vec::with_capacity(12)),
            fan: Vec::with_capacity(48),
            tri_buf: Vec::with_capacity(16),
        }
    }

    fn point_key(&self, g: [usize; 3]) -> u64 {
        g[0] as u64 * self.strides.0 + g[1] as u64 * self.strides.1 + g[2] as u64
    }

    /// The surface in the cell whose lowest grid point is `g`.
    fn cell(&mut self, g: [usize; 3]) {
        let mut mask = 0u32;
        for c in 0..8 {
            self.v[c] = self.grid[[g[0] + (c & 1), g[1] + ((c >> 1) & 1), g[2] + (c >> 2)]] - self.opts.level;
            if self.v[c] > 0.0 {
                mask |= 1 << c;
            }
        }
        if mask == 0 || mask == 255 {
            return;
        }
        let (succ, joined_faces, ambiguous_faces) = face_segments(&self.v, mask, self.opts.ambiguity);
        for (e, &next) in succ.iter().enumerate() {
            self.local_vertex[e] = u32::MAX;
            if next != usize::MAX {
                self.edge_vertex(g, e);
            }
        }
        let n_cycles = self.chain_cycles(&succ);
        // Two polygons around two same-sign regions that the trilinear interpolant joins
        // through the cell: one tube instead of two discs.
        let tube = self.opts.ambiguity == Ambiguity::AsymptoticDecider
            && n_cycles == 2
            && self.cycles[0].len() >= 3
            && self.cycles[1].len() >= 3
            && joined_inside(&self.v, mask, joined_faces, ambiguous_faces);
        self.fill_fan(mask, joined_faces, tube, n_cycles);
        self.emit_fan();
    }

    /// The vertex of crossed local edge `e` of the cell at `g`, welded with the other
    /// cells' (and, for an end exactly on the level, with every edge at that grid point).
    fn edge_vertex(&mut self, g: [usize; 3], e: usize) {
        let lo = edge_lower_corner(e);
        let hi = lo | (1 << (e / 4));
        let (vl, vh) = (self.v[lo], self.v[hi]);
        let gl = [g[0] + (lo & 1), g[1] + ((lo >> 1) & 1), g[2] + (lo >> 2)];
        let axis = e / 4;
        // Exactly on the level: the vertex is the grid point, shared by its edges.
        self.local_faces[e] = self.edge_faces[e];
        let (key, pos) = if vl == 0.0 || vh == 0.0 {
            let (gp, c) = if vl == 0.0 {
                (gl, lo)
            } else {
                ([gl[0] + (axis == 0) as usize, gl[1] + (axis == 1) as usize, gl[2] + (axis == 2) as usize], hi)
            };
            self.local_faces[e] = corner_face_mask(c);
            (3 * self.n_points + self.point_key(gp), gp.map(|c| c as f64))
        } else {
            let wl = 1.0 / (f64::EPSILON + vl.abs());
            let wh = 1.0 / (f64::EPSILON + vh.abs());
            let mut p = gl.map(|c| c as f64);
            p[axis] += wh / (wl + wh);
            (axis as u64 * self.n_points + self.point_key(gl), p)
        };
        let (positions, opts) = (&mut self.positions, self.opts);
        self.local_vertex[e] = *self.vertex_of.entry(key).or_insert_with(|| {
            positions.push([
                opts.origin[0] + opts.spacing[0] * pos[0],
                opts.origin[1] + opts.spacing[1] * pos[1],
                opts.origin[2] + opts.spacing[2] * pos[2],
            ]);
            (positions.len() - 1) as u32
        });
    }

    /// Chains the face segments (`succ[entry edge] = exit edge`) into closed polygons in
    /// `self.cycles` (consecutive repeated vertices merged); returns how many.
    fn chain_cycles(&mut self, succ: &[usize; 12]) -> usize {
        let mut n_cycles = 0;
        let mut seen = 0u32;
        for start in 0..12 {
            if succ[start] == usize::MAX || seen & (1 << start) != 0 {
                continue;
            }
            let cycle = &mut self.cycles[n_cycles];
            n_cycles += 1;
            cycle.clear();
            let mut e = start;
            while e < 12 && seen & (1 << e) == 0 {
                seen |= 1 << e;
                let vid = self.local_vertex[e];
                if cycle.last().map(|c| c.0) != Some(vid) {
                    cycle.push((vid, self.local_faces[e]));
                }
                e = succ[e];
            }
            if cycle.len() > 1 && cycle.first().map(|c| c.0) == cycle.last().map(|c| c.0) {
                cycle.pop();
            }
        }
        n_cycles
    }

    /// The cell's triangles into `self.fan`: the classic table's where the cell's polygons
    /// are the table's (every face separating its above corners, no tube), else a tube or a
    /// fan per polygon.
    fn fill_fan(&mut self, mask: u32, joined_faces: u8, tube: bool, n_cycles: usize) {
        self.fan.clear();
        let classic = match self.opts.ambiguity {
            Ambiguity::SeparateAbove => true,
            Ambiguity::AsymptoticDecider => joined_faces == 0 && !tube,
            Ambiguity::JoinAbove => false,
        };
        if classic && classic_triangles(mask, &self.local_vertex, &mut self.fan) {
            // The table's triangles are in `fan`.
        } else if tube {
            let (c1, c2) = self.cycles.split_at(1);
            tube_triangles(&c1[0], &c2[0], &mut self.fan, &mut self.positions);
        } else {
            for cycle in &self.cycles[..n_cycles] {
                triangulate(cycle, &mut self.tri_buf, &mut self.positions);
                self.fan.extend_from_slice(&self.tri_buf);
            }
        }
    }

    /// Appends the non-degenerate triangles of `self.fan`, oriented for `opts.inside`.
    fn emit_fan(&mut self) {
        for tri in &self.fan {
            if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
                continue;
            }
            self.triangles.push(match self.opts.inside {
                Inside::Above => *tri,
                Inside::Below => [tri[0], tri[2], tri[1]],
            });
        }
    }
}
