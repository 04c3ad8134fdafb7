//! Target solids for the signed-distance regulariser and for labelling: a triangle mesh
//! (through the occupancy crate's oracle) by its winding number, as a thin shell, or as
//! what a flood fill from outside leaves enclosed; and an analytic sphere.

use occupancy::flood::FloodGrid;
use occupancy::{MeshOracle, WindingMode, Workspace};
use rayon::prelude::*;

use crate::losses::{Located, Solid};

/// Points per parallel chunk (fixed, so results never depend on the thread count).
const CHUNK: usize = 256;

/// A triangle mesh as a solid: inside by the workspace's one rule
/// ([`occupancy::Config::is_inside_winding`]: |generalized winding number| ≥ 0.5, fast mode
/// with the exact fallback on both sides of the threshold), closest point by BVH.
pub struct MeshSolid<'a> {
    /// The oracle, built on the mesh in the frame of the queries.
    pub oracle: &'a MeshOracle,
}

impl Solid for MeshSolid<'_> {
    /// Inside test for each point ([`MeshOracle::is_inside`]), through the oracle's batch
    /// [`MeshOracle::inside`] (Morton order, packet traversal: the same answers, several
    /// times faster); points it refuses (non-finite coordinates) are tested one by one.
    fn inside(&self, points: &[[f64; 3]]) -> Vec<bool> {
        if let Ok(v) = self.oracle.inside(points) {
            return v;
        }
        let mut out = vec![false; points.len()];
        out.par_chunks_mut(CHUNK).zip(points.par_chunks(CHUNK)).for_each(|(o, ps)| {
            let mut ws = Workspace::new();
            for (o, &p) in o.iter_mut().zip(ps) {
                *o = self.oracle.is_inside(p, WindingMode::Fast, &mut ws);
            }
        });
        out
    }

    /// Inside test as [`MeshSolid::inside`]; closest points one chunk of [`CHUNK`] at a
    /// time in input order (each chunk's search starts afresh, so the points found never
    /// depend on the thread count).
    fn locate(&self, points: &[[f64; 3]]) -> Vec<Located> {
        let inside = self.inside(points);
        let mut out = vec![Located { inside: false, closest: [0.0; 3] }; points.len()];
        out.par_chunks_mut(CHUNK).zip(points.par_chunks(CHUNK)).zip(inside.par_chunks(CHUNK)).for_each(
            |((o, ps), ins)| {
                let mut ws = Workspace::new();
                for ((o, &p), &inside) in o.iter_mut().zip(ps).zip(ins) {
                    let closest = self.oracle.closest_point(p, &mut ws).point;
                    *o = Located { inside, closest };
                }
            },
        );
        out
    }
}

/// A surface thickened into a solid: the points within `half_thickness` of the mesh (an
/// offset band, closed by half-cylinders along open boundaries). This is the target when the
/// mesh encloses no volume (a zero-thickness sheet, a lone open patch), where the winding
/// number rule of [`MeshSolid`] would leave nothing inside.
pub struct ShellSolid<'a> {
    /// The oracle, built on the mesh in the frame of the queries (closest points by BVH).
    pub oracle: &'a MeshOracle,
    /// Unit normal of each triangle of the oracle's mesh (any orientation): the direction
    /// off the band's middle for a point exactly on the mesh.
    pub normals: Vec<[f64; 3]>,
    /// Half the band's thickness, in the frame of the queries (> 0).
    pub half_thickness: f64,
}

impl<'a> ShellSolid<'a> {
    /// The band of half-thickness `half_thickness` around `mesh` (the mesh `oracle` was
    /// built on, same frame).
    pub fn new(oracle: &'a MeshOracle, mesh: &mesh_io::TriMesh, half_thickness: f64) -> Self {
        let normals = (0..mesh.triangles.len()).map(|t| unit_normal(mesh, t)).collect();
        ShellSolid { oracle, normals, half_thickness }
    }
}

impl Solid for ShellSolid<'_> {
    fn locate(&self, points: &[[f64; 3]]) -> Vec<Located> {
        let h = self.half_thickness;
        let mut out = vec![Located { inside: false, closest: [0.0; 3] }; points.len()];
        out.par_chunks_mut(CHUNK).zip(points.par_chunks(CHUNK)).for_each(|(o, ps)| {
            let mut ws = Workspace::new();
            for (o, &p) in o.iter_mut().zip(ps) {
                let c = self.oracle.closest_point(p, &mut ws);
                let d = c.squared_distance.sqrt();
                let dir = if d > 1e-12 * h {
                    [0, 1, 2].map(|i| (p[i] - c.point[i]) / d)
                } else {
                    self.normals.get(c.triangle as usize).copied().unwrap_or([0.0, 0.0, 1.0])
                };
                *o = Located { inside: d <= h, closest: [0, 1, 2].map(|i| c.point[i] + h * dir[i]) };
            }
        });
        out
    }
}

/// A soup as a solid by flood fill ([`FloodGrid`]): what the flood from outside cannot
/// reach is inside, and the boundary lies on the input's surface, not a wall radius off.
/// A point near the surface takes the side of the closest surface point it lies on: it
/// steps off that point, away from the surface, to the first cell outside the walls
/// ([`FloodGrid::side`]). A surface with the outside on both sides (a single-sided panel, a
/// sheet, an open box's walls, a plate thinner than about two cells) is thickened into a
/// band of half-thickness `sheet_half_thickness`, so that panels and slats are kept. Where
/// the step finds no cell outside the walls (inside a rod or a crevice narrower than the
/// grid resolves) the point is inside, as the flood closes such gaps; the winding number
/// is never asked, so flipped faces change nothing.
pub struct FloodSolid<'a> {
    /// The oracle, built on the mesh in the frame of the queries.
    pub oracle: &'a MeshOracle,
    /// The flood-filled grid, built on the same mesh and frame.
    pub grid: FloodGrid,
    /// Unit normal of each triangle of the oracle's mesh (any orientation).
    pub normals: Vec<[f64; 3]>,
    /// Half the thickness of the band around sheets (> 0).
    pub sheet_half_thickness: f64,
}

/// Which solid boundary a surface point is on ([`FloodSolid::surface_side`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SurfaceSide {
    /// Enclosed on one side, outside on the other: on the solid's boundary.
    Boundary,
    /// Enclosed on both sides: an interior face (doubled, buried, between touching parts).
    Interior,
    /// Outside on both sides: a sheet, thickened into a band.
    Sheet,
    /// Neither side has a cell outside the walls (inside a rod, a crevice): inside.
    Crevice,
}

impl<'a> FloodSolid<'a> {
    /// The flood solid of `mesh` (the mesh `oracle` was built on, same frame) with grid
    /// cells of side `cell` and sheets thickened to half-thickness `sheet_half_thickness`.
    ///
    /// # Errors
    /// [`FloodGrid::build`]'s.
    pub fn new(
        oracle: &'a MeshOracle,
        mesh: &mesh_io::TriMesh,
        cell: f64,
        sheet_half_thickness: f64,
    ) -> Result<Self, occupancy::OccupancyError> {
        let grid = FloodGrid::build(&mesh.positions, &mesh.triangles, cell)?;
        let normals = (0..mesh.triangles.len()).map(|t| unit_normal(mesh, t)).collect();
        Ok(FloodSolid { oracle, grid, normals, sheet_half_thickness })
    }

    /// The side a surface point `x` with unit normal `n` (either orientation) is on.
    pub fn surface_side(&self, x: [f64; 3], n: [f64; 3]) -> SurfaceSide {
        let minus = n.map(|c| -c);
        match (self.grid.side(x, n), self.grid.side(x, minus)) {
            (Some(false), Some(false)) => SurfaceSide::Sheet,
            // Outside on one side; enclosed, or walls too close to step out of, on the other.
            (Some(false), _) | (_, Some(false)) => SurfaceSide::Boundary,
            (None, None) => SurfaceSide::Crevice,
            _ => SurfaceSide::Interior,
        }
    }

    fn locate_one(&self, p: [f64; 3], ws: &mut Workspace, need_closest: bool) -> Located {
        use occupancy::flood::Cell;
        let cell = self.grid.cell_at(p);
        // Off the walls a point is at least the wall radius from the surface, so an outside
        // cell's point can only be in a sheet's band when the band is wider.
        let settled =
            cell == Cell::Enclosed || (cell == Cell::Outside && self.sheet_half_thickness < self.grid.wall_radius());
        if settled && !need_closest {
            return Located { inside: cell == Cell::Enclosed, closest: p };
        }
        let c = self.oracle.closest_point(p, ws);
        let d = c.squared_distance.sqrt();
        let h = self.sheet_half_thickness;
        let dir = if d > 1e-12 * h {
            [0, 1, 2].map(|i| (p[i] - c.point[i]) / d)
        } else {
            self.normals.get(c.triangle as usize).copied().unwrap_or([0.0, 0.0, 1.0])
        };
        let sheet = Located { inside: d <= h, closest: [0, 1, 2].map(|i| c.point[i] + h * dir[i]) };
        if cell != Cell::Wall {
            // Off the walls: the cell decides; the closest boundary point is the band's
            // when the nearest surface is a sheet.
            let inside = cell == Cell::Enclosed;
            let on_sheet = !inside && self.grid.side(c.point, dir.map(|x| -x)) == Some(false);
            return if on_sheet { sheet } else { Located { inside, closest: c.point } };
        }
        match self.grid.side(c.point, dir) {
            Some(false) if self.grid.side(c.point, dir.map(|x| -x)) == Some(false) => sheet,
            Some(false) => Located { inside: false, closest: c.point },
            // The enclosed side, or walls too close to step out of (a rod, a crevice).
            _ => Located { inside: true, closest: c.point },
        }
    }

    fn locate_all(&self, points: &[[f64; 3]], need_closest: bool) -> Vec<Located> {
        let mut out = vec![Located { inside: false, closest: [0.0; 3] }; points.len()];
        out.par_chunks_mut(CHUNK).zip(points.par_chunks(CHUNK)).for_each(|(o, ps)| {
            let mut ws = Workspace::new();
            for (o, &p) in o.iter_mut().zip(ps) {
                *o = self.locate_one(p, &mut ws, need_closest);
            }
        });
        out
    }
}

impl Solid for FloodSolid<'_> {
    fn locate(&self, points: &[[f64; 3]]) -> Vec<Located> {
        self.locate_all(points, true)
    }

    /// Only points in wall cells need a closest point.
    fn inside(&self, points: &[[f64; 3]]) -> Vec<bool> {
        self.locate_all(points, false).into_iter().map(|l| l.inside).collect()
    }
}

/// Unit normal of triangle `t` of `mesh` (counter-clockwise orientation; z for a
/// degenerate triangle).
pub fn unit_normal(mesh: &mesh_io::TriMesh, t: usize) -> [f64; 3] {
    let [a, b, c] = mesh.triangles[t].map(|v| mesh.positions[v as usize]);
    let (u, v) = ([0, 1, 2].map(|i| b[i] - a[i]), [0, 1, 2].map(|i| c[i] - a[i]));
    let n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
    let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if l > 0.0 {
        n.map(|x| x / l)
    } else {
        [0.0, 0.0, 1.0]
    }
}

/// A solid ball: the workspace's one sphere type ([`mesh_io::shapes::Sphere`]), also the
/// reference of the certified sphere Hausdorff in `metrics`.
pub use mesh_io::shapes::Sphere;

impl Solid for Sphere {
    fn locate(&self, points: &[[f64; 3]]) -> Vec<Located> {
        points
            .iter()
            .map(|&p| {
                let d = self.center_distance(p);
                let dir = if d > 0.0 { [0, 1, 2].map(|c| (p[c] - self.center[c]) / d) } else { [1.0, 0.0, 0.0] };
                Located { inside: d <= self.radius, closest: [0, 1, 2].map(|c| self.center[c] + self.radius * dir[c]) }
            })
            .collect()
    }
}
