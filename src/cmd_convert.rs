//! `voronoi-fit convert MESH -o OUT [--normalize] [--weld-tolerance T]`: read any supported
//! mesh, write GLB / glTF / OBJ / PLY (chosen by the output extension), atomically.

use std::path::PathBuf;

use mesh_io::OutputFormat;

use crate::cli_error::CliError;

#[derive(clap::Args)]
pub struct Args {
    /// Input mesh: .obj, .stl, .ply, .off, .gltf or .glb.
    pub mesh: PathBuf,
    /// Output file: .glb, .gltf (+ .bin beside it), .obj or binary .ply.
    #[arg(short, long)]
    pub output: PathBuf,
    #[arg(long, default_value = "flat", value_parser = mesh_io::Normals::parse, value_name = "flat|smooth|crease[:DEG]",
          help = crate::output::NORMALS_HELP)]
    pub normals: mesh_io::Normals,
    /// Map the mesh into the unit cube (uniform scale, centred) before writing.
    #[arg(long)]
    pub normalize: bool,
    /// Empty space left on each side of the unit cube by --normalize, in unit-cube lengths.
    #[arg(long, default_value_t = 0.05, requires = "normalize")]
    pub margin: f64,
    /// Merge vertices at most this fraction of the bounding-box diagonal apart before
    /// writing (closes the hairline cracks of CAD exports; 1e-6 is typical), dropping the
    /// triangles that collapse. 0, or between 1e-15 and 1e-2.
    #[arg(long, value_name = "FRACTION", value_parser = mesh_io::weld::parse_tolerance)]
    pub weld_tolerance: Option<f64>,
}

pub fn run(args: Args) -> Result<(), CliError> {
    // Everything about the output is checked before the input is read.
    let format = OutputFormat::from_path(&args.output)?;
    if !(0.0..0.5).contains(&args.margin) {
        return Err(CliError::input(format!("--margin {} is outside [0, 0.5).", args.margin)));
    }
    mesh_io::check_output_location(&args.output)?;
    let mut mesh = mesh_io::read_mesh(&args.mesh)?;
    if let Some(t) = args.weld_tolerance {
        let (welded, w) = mesh_io::weld_tolerance(&mesh, t);
        mesh = welded;
        crate::output::out!(
            "welded at {:e} × diagonal ({:.3e}): {} → {} vertices, {} degenerate triangles dropped",
            w.relative_tolerance,
            w.absolute_tolerance,
            w.vertices_before,
            w.vertices_after,
            w.degenerate_triangles_dropped
        );
    }
    if args.normalize {
        let t = mesh_io::UnitCubeTransform::of_mesh(&mesh, args.margin).ok_or_else(|| {
            CliError::input(format!(
                "{}: all vertices coincide, so the mesh cannot be scaled into the unit cube.",
                args.mesh.display()
            ))
        })?;
        mesh = t.mesh_to_unit(&mesh);
    } else if format.stores_f32() {
        mesh_io::check_f32_resolution(&mesh, &args.mesh)?;
    }
    mesh_io::write_mesh_with(&args.output, &mesh, args.normals)?;
    Ok(())
}
