//! Which coordinates this program handles: the representable range, checked on every read.
//!
//! Every stage computes in f64, and every glTF output stores f32 (the format's only float
//! type). A mesh passes [`check_representable`] when
//!
//! - every coordinate satisfies |x| ≤ [`MAX_ABS_COORDINATE`] = 1e30, and
//! - its bounding-box diagonal is 0 (all vertices coincide; later stages say so) or at least
//!   [`MIN_DIAGONAL`] = 1e-30.
//!
//! Why 1e30 and 1e-30: float32 overflows at 3.4e38 and stops being normal below 1.2e-38,
//! so 1e30 leaves eight decades of headroom for the outputs (crust cells reach beyond the
//! mesh's box, normals and matrices multiply coordinates). In f64, the largest products
//! the geometry forms — squared distances, volumes and orientation determinants (cubes),
//! in-sphere determinants (fourth and fifth powers) — of lengths in [1e-30, 1e30] stay
//! within [1e-150, 1e150], far inside f64's normal range [2.2e-308, 1.8e308]. Outside it,
//! a mesh at 1e300 gives infinite volumes and an all-infinite GLB.
//!
//! [`check_f32_resolution`] is the separate check for writing a mesh in its own frame as
//! float32 (GLB / glTF): a mesh far from the origin compared with its size, such as a
//! 10 m part at 1e6 m, is fine in f64 but float32 would store it in steps coarser than
//! [`MIN_F32_STEPS_PER_DIAGONAL`]⁻¹ of its size. It is not part of [`crate::read_mesh`],
//! because `info` and lossless outputs (OBJ, PLY) are unaffected.

use std::path::Path;

use crate::error::{ErrorKind, Location, MeshError};
use crate::TriMesh;

/// The largest |coordinate| any input may have (see the module documentation).
pub const MAX_ABS_COORDINATE: f64 = 1e30;

/// The smallest non-zero bounding-box diagonal a mesh may have.
pub const MIN_DIAGONAL: f64 = 1e-30;

/// float32 output must resolve the bounding-box diagonal in at least this many steps.
pub const MIN_F32_STEPS_PER_DIAGONAL: f64 = 1e4;

/// The hint of every range error.
const RESCALE: &str = "Rescale the mesh (for example convert millimetres to metres, or the reverse) in the \
     program that made it, so that coordinates lie within ±1e30 and the mesh spans at least 1e-30";

/// Index and value of the first coordinate of `p` outside ±[`MAX_ABS_COORDINATE`] (NaN
/// included), if any.
pub(crate) fn out_of_range(p: &[f64; 3]) -> Option<(usize, f64)> {
    p.iter().position(|c| c.is_nan() || c.abs() > MAX_ABS_COORDINATE).map(|k| (k, p[k]))
}

/// The error for a coordinate outside the representable range, or not finite. `what` names
/// the place in words ("vertex 3", "corner 1 of triangle 7"), `location` for the machine.
pub(crate) fn coordinate_error(path: &Path, location: Location, what: &str, axis: usize, value: f64) -> MeshError {
    let axis = ["x", "y", "z"][axis.min(2)];
    if !value.is_finite() {
        return MeshError::new(
            ErrorKind::NonFinite,
            path,
            location,
            format!("{what} has {axis} = {}, not a finite number", short(value)),
        );
    }
    MeshError::new(
        ErrorKind::Unrepresentable,
        path,
        location,
        format!(
            "{what} has {axis} = {}, beyond the ±{:.0e} this program handles (float32 output such as GLB overflows at 3.4e38)",
            short(value),
            MAX_ABS_COORDINATE
        ),
    )
    .hint(format!("{RESCALE}."))
}

/// A number in short scientific notation (`1.000e300`), as every range message prints it.
pub(crate) fn short(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.3e}")
    } else {
        format!("{x}")
    }
}

/// Check that `mesh` lies in the representable range: finite coordinates with
/// |x| ≤ [`MAX_ABS_COORDINATE`], and a bounding-box diagonal that is 0 or at least
/// [`MIN_DIAGONAL`]. [`crate::read_mesh`] applies it to every file; call it on meshes built
/// by other means. `path` names the mesh in the error.
///
/// # Errors
/// [`ErrorKind::NonFinite`] for a NaN or infinite coordinate, [`ErrorKind::Unrepresentable`]
/// otherwise; the location is the first offending vertex (its index in `mesh.positions`) or
/// the whole file for the extent, numbers printed as `1.000e300`.
///
/// # Example
/// ```
/// let mesh = mesh_io::TriMesh { positions: vec![[1e300, 0.0, 0.0], [0.0; 3], [0.0, 1.0, 0.0]], triangles: vec![[0, 1, 2]] };
/// let e = mesh_io::check_representable(&mesh, "big.obj".as_ref()).unwrap_err();
/// assert_eq!(e.kind, mesh_io::ErrorKind::Unrepresentable);
/// assert!(e.to_string().starts_with("big.obj, vertex 0: vertex 0 has x = 1.000e300"));
/// ```
pub fn check_representable(mesh: &TriMesh, path: &Path) -> Result<(), MeshError> {
    for (i, p) in mesh.positions.iter().enumerate() {
        if let Some((axis, value)) = out_of_range(p) {
            let location = Location::Element { kind: "vertex", index: i };
            return Err(coordinate_error(path, location, &format!("vertex {i}"), axis, value));
        }
    }
    let diagonal = mesh.diagonal();
    if diagonal > 0.0 && diagonal < MIN_DIAGONAL {
        return Err(MeshError::new(
            ErrorKind::Unrepresentable,
            path,
            Location::File,
            format!(
                "the mesh spans only {} (bounding-box diagonal), below the {:.0e} this program handles (float32 output such as GLB would collapse its vertices)",
                short(diagonal),
                MIN_DIAGONAL
            ),
        )
        .hint(format!("{RESCALE}.")));
    }
    Ok(())
}

/// The spacing of float32 values at the mesh's largest |coordinate|: the resolution of a
/// GLB / glTF written in the mesh's own frame. 0 for an empty mesh.
pub fn f32_step(mesh: &TriMesh) -> f64 {
    let m = mesh.positions.iter().flatten().fold(0.0f64, |m, c| m.max(c.abs()));
    let f = m as f32;
    if !f.is_finite() {
        return f64::INFINITY;
    }
    // The gap above the float32 nearest to m; below it the gap is at most this.
    let up = f32::from_bits(f.to_bits() + 1);
    if up.is_finite() {
        (up as f64) - (f as f64)
    } else {
        f64::INFINITY
    }
}

/// Check that float32 output in the mesh's own frame (GLB, glTF) resolves the mesh: the
/// float32 spacing at its largest |coordinate| ([`f32_step`]) must be at most the
/// bounding-box diagonal / [`MIN_F32_STEPS_PER_DIAGONAL`]. Meshes whose vertices all
/// coincide pass (there is nothing to resolve). Call it before long work whose output is
/// GLB / glTF in the input's frame; [`crate::OutputFormat::stores_f32`] tells which outputs.
///
/// # Errors
/// [`ErrorKind::Unrepresentable`] naming `path`, with the step and the diagonal.
pub fn check_f32_resolution(mesh: &TriMesh, path: &Path) -> Result<(), MeshError> {
    let diagonal = mesh.diagonal();
    let step = f32_step(mesh);
    if diagonal > 0.0 && step * MIN_F32_STEPS_PER_DIAGONAL > diagonal {
        let (lo, hi) = mesh.bounding_box();
        let center = [0, 1, 2].map(|k| short(0.5 * lo[k] + 0.5 * hi[k]));
        return Err(MeshError::new(
            ErrorKind::Unrepresentable,
            path,
            Location::File,
            format!(
                "the mesh spans {} but sits at ({}, {}, {}): float32 (GLB / glTF output) stores it in steps of {}, coarser than 1/{:.0e} of its size",
                short(diagonal),
                center[0],
                center[1],
                center[2],
                short(step),
                MIN_F32_STEPS_PER_DIAGONAL
            ),
        )
        .hint("Move the mesh near the origin (for example `voronoi-fit convert MESH --normalize -o moved.ply`), or write .obj or .ply, which keep full precision."));
    }
    Ok(())
}
