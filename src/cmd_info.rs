//! `voronoi-fit info MESH [--json]`: the topology report.

use std::path::PathBuf;

use crate::cli_error::CliError;

#[derive(clap::Args)]
pub struct Args {
    /// Mesh file: .obj, .stl, .ply, .off, .gltf or .glb.
    pub mesh: PathBuf,
    /// Print the report as JSON (stable layout, documented in the README).
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: Args) -> Result<(), CliError> {
    let mesh = mesh_io::read_mesh(&args.mesh)?;
    let r = mesh_io::TopologyReport::of(&mesh);
    if args.json {
        #[derive(serde::Serialize)]
        struct Out<'a> {
            file: String,
            #[serde(flatten)]
            report: &'a mesh_io::TopologyReport,
        }
        let out = Out { file: args.mesh.display().to_string(), report: &r };
        crate::output::out!("{}", serde_json::to_string_pretty(&out).map_err(anyhow::Error::from)?);
        return Ok(());
    }
    let yes = |b: bool| if b { "yes" } else { "no" };
    crate::output::out!("{}", args.mesh.display());
    crate::output::out!("  vertices            {} ({} referenced)", r.num_vertices, r.num_referenced_vertices);
    crate::output::out!(
        "  faces               {} ({} degenerate, {} duplicate)",
        r.num_faces,
        r.num_degenerate_faces,
        r.num_duplicate_faces
    );
    crate::output::out!(
        "  edges               {} ({} boundary in {} loops, {} non-manifold)",
        r.num_edges,
        r.num_boundary_edges,
        r.num_boundary_loops,
        r.num_non_manifold_edges
    );
    crate::output::out!("  non-manifold verts  {}", r.num_non_manifold_vertices);
    crate::output::out!("  components          {}", r.num_components);
    crate::output::out!("  Euler characteristic {}", r.euler_characteristic);
    match r.genus {
        Some(g) => println!("  genus               {g}"),
        None => println!("  genus               n/a (not closed, manifold and oriented)"),
    }
    crate::output::out!("  closed              {}", yes(r.is_closed));
    crate::output::out!("  manifold            {}", yes(r.is_manifold));
    crate::output::out!("  consistently oriented {}", yes(r.is_orientation_consistent));
    crate::output::out!("  signed volume       {:.9e}", r.signed_volume);
    crate::output::out!("  surface area        {:.9e}", r.surface_area);
    crate::output::out!("  bounding box        {:?} .. {:?}", r.bbox_min, r.bbox_max);
    Ok(())
}
