//! The crust as written: mapped to the mesh frame, rounded as the file stores it, and
//! checked exactly in that form.
//!
//! [`Crust::extract`](crate::Crust::extract) checks the crust in the unit cube, in f64.
//! A file holds something else: the positions mapped back to the input's frame and
//! rounded to the format's floats (f32 for GLB / glTF, f64 for OBJ and PLY as
//! `mesh_io` writes them), read back by software that welds bitwise-equal positions.
//! Rounding can make distinct vertices coincide (degenerate triangles, pinched vertices,
//! open edges after welding) or move them so that triangles cross, and split vertices
//! (inside cells touching along an edge or at a point share a position) weld into
//! non-manifold vertices. [`finalize`] produces the mesh exactly as it will be written and
//! read, repairs it where rounding broke it, and checks it with
//! [`check_crust`]; it never returns a mesh that fails.

use std::path::Path;

use mesh_io::{OutputFormat, TriMesh, UnitCubeTransform};

use crate::check::{check_crust, find_defects, CrustCheck};
use crate::error::CrustError;
use crate::extract::Crust;
use crate::resolve::{attempt, coincident_groups, resolve, split_loops, Target};

/// How a format stores coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Precision {
    /// float32 (GLB, glTF).
    F32,
    /// float64, lossless (OBJ and PLY as `mesh_io` writes them).
    F64,
}

impl Precision {
    /// The precision `format` stores positions in.
    pub fn of_format(format: OutputFormat) -> Precision {
        if format.stores_f32() {
            Precision::F32
        } else {
            Precision::F64
        }
    }

    /// The precision of the format `path`'s extension names.
    ///
    /// # Errors
    /// An unknown extension ([`OutputFormat::from_path`]).
    pub fn of_path(path: &Path) -> Result<Precision, mesh_io::MeshError> {
        OutputFormat::from_path(path).map(Precision::of_format)
    }

    /// `x` rounded as the writer stores it (round to nearest even; overflow to ±∞).
    pub fn round(self, x: f64) -> f64 {
        match self {
            Precision::F32 => x as f32 as f64,
            Precision::F64 => x,
        }
    }

    fn target(self) -> Target {
        match self {
            // f32: merging up to 2⁻¹⁶ of the extent, some 128 ulps at the mesh's own scale.
            Precision::F32 => Target {
                round: |x| x as f32 as f64,
                epsilon: f32::EPSILON as f64,
                distinct_positions: true,
                max_merge: 1.0 / (1u64 << 16) as f64,
            },
            Precision::F64 => Target {
                round: |x| x,
                epsilon: f64::EPSILON,
                distinct_positions: true,
                max_merge: 1.0 / (1u64 << 26) as f64,
            },
        }
    }
}

/// The map from the crust's frame (the unit cube) to the output's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FrameMap {
    /// Write the crust as it is.
    Identity,
    /// [`UnitCubeTransform::from_unit`], as the main job maps its outputs.
    UnitCube(UnitCubeTransform),
    /// A row-major affine 4×4 matrix on homogeneous column vectors, as a sites file stores
    /// it ([`crate::SitesFile::to_mesh_frame`] evaluates it the same way).
    Matrix([[f64; 4]; 4]),
}

impl From<UnitCubeTransform> for FrameMap {
    fn from(t: UnitCubeTransform) -> Self {
        FrameMap::UnitCube(t)
    }
}

impl From<&UnitCubeTransform> for FrameMap {
    fn from(t: &UnitCubeTransform) -> Self {
        FrameMap::UnitCube(*t)
    }
}

impl From<[[f64; 4]; 4]> for FrameMap {
    fn from(m: [[f64; 4]; 4]) -> Self {
        FrameMap::Matrix(m)
    }
}

impl FrameMap {
    /// Map one point (f64, before the output's rounding).
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        match self {
            FrameMap::Identity => p,
            FrameMap::UnitCube(t) => t.from_unit(p),
            FrameMap::Matrix(m) => [0, 1, 2].map(|r| m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + m[r][3]),
        }
    }

    /// Whether the map mirrors (triangles are then reversed to stay counter-clockwise
    /// seen from outside).
    pub fn mirrors(&self) -> bool {
        match self {
            FrameMap::Identity => false,
            FrameMap::UnitCube(t) => t.scale < 0.0,
            FrameMap::Matrix(m) => linear_determinant(m) < 0.0,
        }
    }

    /// `mesh` mapped by this map, every triangle reversed when the map mirrors (so outward
    /// stays outward), without rounding or checks: for outputs that are not crusts (the
    /// convex cells). The one place the workspace maps a unit-cube mesh to a frame by a
    /// general matrix; [`mesh_io::UnitCubeTransform::mesh_from_unit`] is the same for the
    /// normalisation's transform.
    pub fn map_mesh(&self, mesh: &TriMesh) -> TriMesh {
        let flip = self.mirrors();
        TriMesh {
            positions: mesh.positions.iter().map(|&p| self.apply(p)).collect(),
            triangles: mesh.triangles.iter().map(|t| if flip { [t[0], t[2], t[1]] } else { *t }).collect(),
        }
    }

    fn check(&self) -> Result<(), CrustError> {
        let bad = match self {
            FrameMap::Identity => false,
            FrameMap::UnitCube(t) => !(t.scale.is_finite() && t.scale != 0.0 && t.center.iter().all(|c| c.is_finite())),
            FrameMap::Matrix(m) => {
                // The determinant of the matrix scaled to entries of at most 1, so that it
                // neither overflows nor underflows for any finite matrix.
                let s = m.iter().flatten().fold(0.0f64, |a, x| a.max(x.abs()));
                let scaled = m.map(|row| row.map(|x| x / s));
                !(m.iter().flatten().all(|x| x.is_finite())
                    && m[3] == [0.0, 0.0, 0.0, 1.0]
                    && s > 0.0
                    && linear_determinant(&scaled) != 0.0)
            }
        };
        if bad {
            return Err(CrustError::Unwritable(format!(
                "the map to the output frame ({self:?}) is not a finite invertible affine map"
            )));
        }
        Ok(())
    }
}

fn linear_determinant(m: &[[f64; 4]; 4]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// A crust ready to write.
#[derive(Clone, Debug)]
pub struct Finalized {
    /// The mesh to write: every position is exactly representable in the output's
    /// precision (the writer stores it unchanged), distinct vertices have distinct
    /// positions (a reader's welding changes nothing), and it passes
    /// [`check_crust`].
    pub mesh: TriMesh,
    /// The exact check of `mesh`.
    pub check: CrustCheck,
    /// Vertices merged into a neighbour because rounding collapsed or crossed what they
    /// bound (0 when rounding broke nothing).
    pub num_merged_vertices: usize,
    /// The largest edge length merged (output units; 0 when none or only coincident
    /// vertices were merged).
    pub merge_distance: f64,
    /// Vertices moved apart, by a few units in the last place into their own solid,
    /// because they shared a position with another vertex (split vertices, or vertices
    /// that rounding made coincident and that could not be merged).
    pub num_separated_vertices: usize,
    /// Components and genus of the crust before rounding, when rounding changed them:
    /// a handle or a gap thinner than a few units in the last place of the output's
    /// floats closed (vertices that close apart weld or had to be merged). `None` when
    /// the written crust has the topology of the exact one.
    pub topology_before: Option<(usize, i64)>,
}

/// A sentence for summaries when rounding to the output's floats changed the crust's
/// topology ([`Finalized::topology_before`]; `None` when it did not).
pub fn topology_note(topology_before: Option<(usize, i64)>) -> Option<String> {
    let (c, g) = topology_before?;
    Some(format!(
        "Rounding to the file's floats merged vertices a few float spacings apart, which changed the topology where \
         the crust is that thin (the exact crust has {c} component(s) of genus {g})."
    ))
}

/// The crust exactly as a file in `precision` will hold it, checked.
///
/// - `crust`: as extracted, in the unit cube; its polygons (Voronoi faces) are rounded and
///   triangulated again, so that rounding that flattens a polygon's corner does not leave a
///   degenerate triangle;
/// - `map`: to the output's frame ([`FrameMap`]; a [`UnitCubeTransform`], a 4×4 matrix,
///   or the identity); triangles are reversed when it mirrors;
/// - `precision`: of the format ([`Precision::of_path`], [`Precision::of_format`]).
///
/// Positions are mapped in f64 and rounded to `precision` as the writer rounds them.
/// Vertices that land on the same position are merged (a reader welds them anyway), and
/// the mesh is rebuilt from the merged polygons; where that is not a valid crust, the
/// vertices around the faulty triangles joined by short edges are merged as well (the
/// repair of [`Crust::extract`](crate::Crust::extract), in units of the output's
/// precision), and copies of one position that must stay apart (split vertices) are
/// moved apart by a few units in the last place into their own solid. The result is
/// checked exactly; when rounding broke nothing it is the mapped mesh itself. Merging may
/// close a handle or a gap only when it is at most a few units in the last place thin
/// (the floats cannot keep it open); [`Finalized::topology_before`] then says so.
///
/// # Errors
/// [`CrustError::Unwritable`] when `map` is not a finite invertible affine map, when a
/// coordinate is not finite in `precision` or beyond the ±1e30 that readers accept (such
/// as a scale of 1e300 with f32), or when rounding breaks the crust beyond repair (too
/// coarse a precision for the mesh's detail; write OBJ or PLY instead). Never a mesh that
/// fails the check.
pub fn finalize(crust: &Crust, map: impl Into<FrameMap>, precision: Precision) -> Result<Finalized, CrustError> {
    finalize_polygons(&crust.mesh, Some(&crust.faces), map.into(), precision)
}

/// [`finalize`] for a crust given only as a triangle mesh (in the unit cube, passing
/// [`check_crust`]): the same, with each triangle as a polygon.
/// Where rounding flattens triangles it repairs less often than [`finalize`] and refuses
/// instead.
///
/// # Errors
/// As [`finalize`].
pub fn finalize_mesh(mesh: &TriMesh, map: impl Into<FrameMap>, precision: Precision) -> Result<Finalized, CrustError> {
    finalize_polygons(mesh, None, map.into(), precision)
}

/// `faces`: polygons over `mesh.positions` that `mesh.triangles` triangulates (`None`: the
/// triangles themselves).
fn finalize_polygons(
    mesh: &TriMesh,
    faces: Option<&[Vec<u32>]>,
    map: FrameMap,
    precision: Precision,
) -> Result<Finalized, CrustError> {
    map.check()?;
    let mut positions = Vec::with_capacity(mesh.positions.len());
    for (i, p) in mesh.positions.iter().enumerate() {
        let q = map.apply(*p).map(|x| {
            let r = precision.round(x);
            if r == 0.0 {
                0.0 // readers weld −0.0 with 0.0
            } else {
                r
            }
        });
        if let Some(k) = (0..3).find(|&k| !(q[k].abs() <= mesh_io::limits::MAX_ABS_COORDINATE)) {
            let what = if q[k].is_finite() { "beyond the ±1e30 that readers accept" } else { "not a finite number" };
            return Err(CrustError::Unwritable(format!(
                "vertex {i} at {p:?} maps to {} = {:e} in the output frame ({precision:?}), {what}; \
                 the transform's scale or offset is out of range",
                ["x", "y", "z"][k],
                q[k]
            )));
        }
        positions.push(q);
    }
    let expect = {
        let r = mesh_io::TopologyReport::of(mesh);
        r.genus.map(|g| (r.num_components, g))
    };
    let flip = map.mirrors();
    let triangles: Vec<[u32; 3]> = mesh.triangles.iter().map(|t| if flip { [t[0], t[2], t[1]] } else { *t }).collect();
    let out = TriMesh { positions, triangles };
    if out.triangles.is_empty() {
        let check = check_crust(&TriMesh::default()).map_err(CrustError::Internal)?;
        return Ok(Finalized {
            mesh: TriMesh::default(),
            check,
            num_merged_vertices: 0,
            merge_distance: 0.0,
            num_separated_vertices: 0,
            topology_before: None,
        });
    }
    // Rounding broke nothing: the mapped mesh itself.
    if coincident_groups(&out).is_empty() {
        if let Ok(check) = find_defects(&out, true) {
            return Ok(Finalized {
                mesh: out,
                check,
                num_merged_vertices: 0,
                merge_distance: 0.0,
                num_separated_vertices: 0,
                topology_before: None,
            });
        }
    }
    // Weld as a reader will, rebuild, and repair what remains.
    let mut first_at: std::collections::HashMap<[u64; 3], u32> = std::collections::HashMap::new();
    let weld: Vec<u32> = (0..out.positions.len() as u32)
        .map(|v| *first_at.entry(out.positions[v as usize].map(f64::to_bits)).or_insert(v))
        .collect();
    let num_welded = weld.iter().enumerate().filter(|&(v, &w)| w as usize != v).count();
    let mut polygons: Vec<Vec<u32>> = match faces {
        Some(f) => f.to_vec(),
        None => mesh.triangles.iter().map(|t| t.to_vec()).collect(),
    };
    if flip {
        polygons.iter_mut().for_each(|p| p.reverse());
    }
    let polygons = split_loops(&polygons, &weld);
    let target = precision.target();
    let unwritable = |e: CrustError| {
        let why = match e {
            CrustError::Internal(m) => m,
            e => e.to_string(),
        };
        CrustError::Unwritable(format!(
            "rounding the crust to {} in the output frame breaks it beyond repair ({why}); write a lossless format \
             (.obj or .ply) instead",
            match precision {
                Precision::F32 => "float32",
                Precision::F64 => "float64",
            }
        ))
    };
    match attempt(&polygons, &out.positions, &target) {
        // Every reader welds coincident positions, so a topology that welding changes is
        // the file's whatever is done (a handle or gap thinner than the floats' spacing).
        Ok((built, check, num_separated)) => {
            let topology_before =
                expect.filter(|&(c, g)| (check.report.num_components, check.report.genus) != (c, Some(g)));
            Ok(Finalized {
                mesh: compact(built.mesh),
                check,
                num_merged_vertices: num_welded,
                merge_distance: 0.0,
                num_separated_vertices: num_separated,
                topology_before,
            })
        }
        Err(first) => {
            let o = resolve(&polygons, &out.positions, &target, first, expect).map_err(unwritable)?;
            Ok(Finalized {
                mesh: compact(o.built.mesh),
                check: o.check,
                num_merged_vertices: num_welded + o.num_merged,
                merge_distance: o.merge_distance,
                num_separated_vertices: o.num_separated,
                topology_before: o.topology_before,
            })
        }
    }
}

/// Drop vertices no triangle uses (the builder makes none; kept for safety), keeping order.
fn compact(mesh: TriMesh) -> TriMesh {
    let mut used = vec![false; mesh.positions.len()];
    for t in &mesh.triangles {
        for &v in t {
            used[v as usize] = true;
        }
    }
    if used.iter().all(|&u| u) {
        return mesh;
    }
    let mut id = vec![u32::MAX; mesh.positions.len()];
    let mut positions = Vec::new();
    for (v, p) in mesh.positions.iter().enumerate() {
        if used[v] {
            id[v] = positions.len() as u32;
            positions.push(*p);
        }
    }
    TriMesh { positions, triangles: mesh.triangles.iter().map(|t| t.map(|v| id[v as usize])).collect() }
}
