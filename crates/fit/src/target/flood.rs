//! The flood solid ([`FloodSolid`]) built on the training pool: its labels, how far it
//! agrees with the winding number (the auto rule's test), and the surface samples sorted
//! by the side they are on (boundary kept, interior faces and crevices left out, sheets moved onto
//! their band's two sides).

use mesh_io::TriMesh;
use occupancy::MeshOracle;
use rayon::prelude::*;
use soft_voronoi::{FloodSolid, MeshSolid, Solid, SurfaceSide, TrainingData};

/// Uniform points of the pool on which the flood and winding solids' volumes are compared.
pub(super) const PROBE: usize = 20_000;

use crate::config::{FLOOD_BOUNDARY_SHARE, FLOOD_DISAGREEMENT, FLOOD_ENCLOSED_SHARE};
use crate::error::FitError;
use crate::report::FloodReport;

/// The flood solid and how it sees the pool, before it is chosen.
pub(super) struct FloodLook<'a> {
    solid: FloodSolid<'a>,
    sides: Vec<SurfaceSide>,
    enclosed_share: f64,
    winding_share: f64,
    disagreement: f64,
}

/// Builds the flood solid of `unit` (the oracle's mesh) with `cells` cells along the
/// longest side of its box and sheets of half-thickness `h(share)`, where `share` is the
/// share of the surface on the solid's boundary or on a sheet (the surface the crust
/// follows), sorts `data`'s surface samples by side, and compares the solid with the
/// winding number on probes: the first [`PROBE`] uniform points of the pool (before
/// `num_uniform`), and the near-surface points from `num_uniform` on whose winding labels
/// are `winding_near`. `data` is not changed.
#[allow(clippy::too_many_arguments)]
pub(super) fn flood_look<'a>(
    oracle: &'a MeshOracle,
    unit: &TriMesh,
    data: &TrainingData,
    num_uniform: usize,
    cells: usize,
    h: impl Fn(f64) -> f64,
    winding_near: &[bool],
) -> Result<FloodLook<'a>, FitError> {
    let (lo, hi) = oracle.bounding_box();
    let longest = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
    let cell = longest / cells.max(1) as f64;
    let mut solid = FloodSolid::new(oracle, unit, cell, 0.0)
        .map_err(|source| FitError::Occupancy { during: "the flood fill", source })?;
    let sides: Vec<SurfaceSide> = data
        .surface
        .par_iter()
        .zip(&data.normals)
        .map(|(&x, &n)| if n == [0.0; 3] { SurfaceSide::Crevice } else { solid.surface_side(x, n) })
        .collect();
    let share = |v: &[bool]| v.iter().filter(|&&b| b).count() as f64 / v.len().max(1) as f64;
    // The volume the flood solid holds without the sheets' bands (whose thickness is the
    // fit's choice, not the input's): enclosed cells, and the enclosed side of the walls.
    let uniform = &data.points[..num_uniform.min(PROBE)];
    let enclosed_share = share(&solid.inside(uniform));
    let winding_share = share(&MeshSolid { oracle }.inside(uniform));
    let followed = sides.iter().filter(|&&s| matches!(s, SurfaceSide::Boundary | SurfaceSide::Sheet)).count();
    solid.sheet_half_thickness = h(followed as f64 / sides.len().max(1) as f64);
    let near = &data.points[num_uniform..(num_uniform + winding_near.len()).min(data.points.len())];
    let flood_near = solid.inside(near);
    let disagreement =
        flood_near.iter().zip(winding_near).filter(|(a, b)| a != b).count() as f64 / near.len().max(1) as f64;
    Ok(FloodLook { solid, sides, enclosed_share, winding_share, disagreement })
}

impl<'a> FloodLook<'a> {
    /// Share of the surface samples on sheets.
    pub(super) fn sheet_share(&self) -> f64 {
        self.sides.iter().filter(|&&s| s == SurfaceSide::Sheet).count() as f64 / self.sides.len().max(1) as f64
    }

    /// The sheets' half-thickness, unit-cube lengths.
    pub(super) fn sheet_half_thickness(&self) -> f64 {
        self.solid.sheet_half_thickness
    }

    /// The auto rule's test ([`FLOOD_BOUNDARY_SHARE`], [`FLOOD_ENCLOSED_SHARE`]).
    pub(super) fn wanted(&self) -> bool {
        let n = self.sides.len() as f64;
        let boundary = self.sides.iter().filter(|&&s| s == SurfaceSide::Boundary).count() as f64;
        let interior = self.sides.iter().filter(|&&s| s == SurfaceSide::Interior).count() as f64;
        let enclosing = boundary >= FLOOD_BOUNDARY_SHARE * n || boundary + interior >= FLOOD_ENCLOSED_SHARE * n;
        enclosing && self.disagreement >= FLOOD_DISAGREEMENT
    }

    /// The report's part, with lengths in input units (`scale` per unit-cube length).
    pub(super) fn report(&self, scale: f64, diagonal: f64) -> FloodReport {
        let h = self.solid.sheet_half_thickness;
        let n = self.sides.len().max(1) as f64;
        let share = |k: SurfaceSide| self.sides.iter().filter(|&&s| s == k).count() as f64 / n;
        let cell = self.solid.grid.cell();
        FloodReport {
            cells: self.solid.grid.dims(),
            cell: cell / scale,
            cell_of_diagonal: cell / diagonal,
            enclosed_share: self.enclosed_share,
            winding_share: self.winding_share,
            disagreement: self.disagreement,
            boundary_share: share(SurfaceSide::Boundary),
            interior_share: share(SurfaceSide::Interior),
            sheet_share: share(SurfaceSide::Sheet),
            crevice_share: share(SurfaceSide::Crevice),
            sheet_half_thickness: h / scale,
            sheet_half_thickness_of_diagonal: h / diagonal,
        }
    }

    /// Takes the flood solid: labels the pool, leaves interior faces out of the surface
    /// samples and moves the sheets' onto their band's two sides (alternately), as the
    /// shell does.
    pub(super) fn apply(self, data: &mut TrainingData) -> FloodSolid<'a> {
        let h = self.solid.sheet_half_thickness;
        data.occupancy = self.solid.inside(&data.points);
        let (mut surface, mut normals) =
            (Vec::with_capacity(data.surface.len()), Vec::with_capacity(data.normals.len()));
        for (i, ((&x, &n), side)) in data.surface.iter().zip(&data.normals).zip(&self.sides).enumerate() {
            match side {
                SurfaceSide::Interior | SurfaceSide::Crevice => continue,
                SurfaceSide::Sheet => {
                    let t = if i % 2 == 0 { h } else { -h };
                    surface.push([0, 1, 2].map(|c| x[c] + t * n[c]));
                }
                SurfaceSide::Boundary => surface.push(x),
            }
            normals.push(n);
        }
        // Keep the pool usable when the flood leaves out nearly all of it.
        if surface.len() >= data.surface.len() / 100 {
            data.surface = surface;
            data.normals = normals;
        }
        self.solid
    }
}
