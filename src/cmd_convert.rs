//! `voronoi-fit convert MESH -o OUT [--normalize]`: read any supported mesh, write
//! GLB / glTF / OBJ / PLY (chosen by the output extension), atomically.

use std::path::PathBuf;

use anyhow::anyhow;

use crate::cli_error::CliError;

#[derive(clap::Args)]
pub struct Args {
    /// Input mesh: .obj, .stl, .ply, .off, .gltf or .glb.
    pub mesh: PathBuf,
    /// Output file: .glb, .gltf (+ .bin beside it), .obj or binary .ply.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Map the mesh into the unit cube (uniform scale, centred) before writing.
    #[arg(long)]
    pub normalize: bool,
    /// Empty space left on each side of the unit cube by --normalize, in unit-cube lengths.
    #[arg(long, default_value_t = 0.05, requires = "normalize")]
    pub margin: f64,
}

pub fn run(args: Args) -> Result<(), CliError> {
    if mesh_io::Format::from_extension(&args.output).is_none()
        || args.output.extension().is_some_and(|e| e.eq_ignore_ascii_case("stl") || e.eq_ignore_ascii_case("off"))
    {
        return Err(CliError::BadInput(anyhow!(
            "{}: the output extension names no format this program writes. Use .glb, .gltf, .obj or .ply.",
            args.output.display()
        )));
    }
    if !(0.0..0.5).contains(&args.margin) {
        return Err(CliError::BadInput(anyhow!("--margin {} is outside [0, 0.5).", args.margin)));
    }
    let mut mesh = mesh_io::read_mesh(&args.mesh)?;
    if args.normalize {
        let t = mesh_io::UnitCubeTransform::of_mesh(&mesh, args.margin).ok_or_else(|| {
            CliError::BadInput(anyhow!(
                "{}: all vertices coincide, so the mesh cannot be scaled into the unit cube.",
                args.mesh.display()
            ))
        })?;
        mesh = t.mesh_to_unit(&mesh);
    }
    mesh_io::write_mesh(&args.output, &mesh)?;
    Ok(())
}
