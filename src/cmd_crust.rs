//! `voronoi-fit crust SITES.npz -o CRUST.glb [--cells CELLS.glb] [--json]`: the watertight
//! crust (and optionally the convex inside cells) of a sites file, in the mesh frame.
//!
//! The crust written is the one checked: [`crust::output::finalize`] maps it to the mesh
//! frame, rounds it as the output format stores it (float32 for GLB / glTF, f64 for OBJ
//! and PLY), repairs what rounding breaks or refuses, and checks it exactly.

use std::path::PathBuf;

use crust::output::{finalize, FrameMap, Precision};
use crust::{Crust, CrustConfig, SitesFile};
use mesh_io::{GltfLayout, OutputFormat, SceneMesh, TriMesh};

use crate::cli_error::{CliError, InFile};

#[derive(clap::Args)]
pub struct Args {
    /// Sites file (.npz with sites, labels, transform, format_version; see docs/reports.md).
    pub sites: PathBuf,
    /// Output crust: .glb, .gltf, .obj or .ply (by extension).
    #[arg(short, long)]
    pub output: PathBuf,
    #[arg(long, default_value = "flat", value_parser = mesh_io::Normals::parse, value_name = "flat|smooth|crease[:DEG]",
          help = crate::output::NORMALS_HELP)]
    pub normals: mesh_io::Normals,
    /// Also write every inside cell as a closed convex polyhedron, one node per cell (.glb
    /// or .gltf).
    #[arg(long)]
    pub cells: Option<PathBuf>,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: Args) -> Result<(), CliError> {
    OutputFormat::from_path(&args.output)?;
    mesh_io::check_output_location(&args.output)?;
    if let Some(c) = &args.cells {
        OutputFormat::from_path_in(c, &[OutputFormat::Glb, OutputFormat::Gltf])?;
        mesh_io::check_output_location(c)?;
    }
    let file = SitesFile::read(&args.sites)?;
    // Extraction checks the crust in the unit cube; `finalize` checks it again exactly as
    // the file will hold it, before anything is written.
    let mut crust = Crust::extract(&file.sites, &file.inside, &CrustConfig::default()).in_file(&args.sites)?;
    let precision = Precision::of_path(&args.output)?;
    let written = finalize(&crust, file.transform, precision).in_file(&args.sites)?;
    let (out, check) = (&written.mesh, &written.check);
    mesh_io::write_mesh_with(&args.output, out, args.normals)?;
    let mut num_cells = 0;
    if let Some(path) = &args.cells {
        let cells = crust.cells().in_file(&args.sites)?;
        let map = FrameMap::Matrix(file.transform);
        num_cells = cells.len();
        let meshes: Vec<(String, TriMesh)> =
            cells.iter().map(|(i, m)| (format!("cell {i}"), map.map_mesh(m))).collect();
        let scene: Vec<SceneMesh> = meshes
            .iter()
            .map(|(name, mesh)| SceneMesh { name, mesh, colors: None, normals: Default::default() })
            .collect();
        let layout = if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("gltf")) {
            GltfLayout::Separate
        } else {
            GltfLayout::Binary
        };
        mesh_io::write_gltf(path, &scene, layout)?;
    }
    let s = &crust.stats;
    let volume = check.report.signed_volume;
    if args.json {
        let j = serde_json::json!({
            "sites": args.sites.display().to_string(),
            "output": args.output.display().to_string(),
            "num_sites": s.num_sites,
            "num_inside": s.num_inside,
            "num_mirrors": s.num_mirrors,
            "num_delaunay_passes": s.num_delaunay_passes,
            "num_polygons": s.num_polygons,
            "num_vertices": out.positions.len(),
            "num_triangles": out.triangles.len(),
            "num_split_vertices": s.num_split_vertices,
            "num_merged_vertices": s.num_merged_vertices,
            "output_precision": format!("{precision:?}").to_lowercase(),
            "num_merged_in_output": written.num_merged_vertices,
            "num_separated_in_output": written.num_separated_vertices,
            "topology_before_rounding": written.topology_before,
            "num_cells": num_cells,
            "genus": check.report.genus,
            "num_components": check.report.num_components,
            "volume": volume,
            "delaunay_seconds": s.delaunay_seconds,
            "total_seconds": s.total_seconds,
        });
        crate::output::out!("{}", serde_json::to_string_pretty(&j).map_err(anyhow::Error::from)?);
    } else {
        crate::output::out!(
            "{}: {} sites ({} inside) -> crust of {} triangles, {} vertices, {} component(s), genus {}, volume {:.6e} (mesh units), closed and manifold, checked as written; {:.3} s.{}",
            args.output.display(),
            s.num_sites,
            s.num_inside,
            out.triangles.len(),
            out.positions.len(),
            check.report.num_components,
            check.report.genus.map_or("n/a".to_string(), |g| g.to_string()),
            volume,
            s.total_seconds,
            crust::output::topology_note(written.topology_before).map_or(String::new(), |n| format!(" {n}"))
        );
    }
    Ok(())
}
