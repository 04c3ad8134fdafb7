//! `voronoi-fit info MESH [--json] [--weld-tolerance T]`: the topology report.

use std::path::PathBuf;

use mesh_io::weld::{count_near_pairs, weld_tolerance, WeldStats, NEAR_PAIR_LIMIT, PROBE_RELATIVE_TOLERANCE};

use crate::cli_error::CliError;

#[derive(clap::Args)]
pub struct Args {
    /// Mesh file: .obj, .stl, .ply, .off, .gltf or .glb.
    pub mesh: PathBuf,
    /// Print the report as JSON (stable layout, documented in docs/reports.md).
    #[arg(long)]
    pub json: bool,
    /// Before the report, merge vertices at most this fraction of the bounding-box diagonal
    /// apart (closes the hairline cracks of CAD exports; 1e-6 is typical), dropping the
    /// triangles that collapse. 0, or between 1e-15 and 1e-2.
    #[arg(long, value_name = "FRACTION", value_parser = mesh_io::weld::parse_tolerance)]
    pub weld_tolerance: Option<f64>,
}

pub fn run(args: Args) -> Result<(), CliError> {
    let mut mesh = mesh_io::read_mesh(&args.mesh)?;
    let weld = args.weld_tolerance.map(|t| {
        let (welded, stats) = weld_tolerance(&mesh, t);
        mesh = welded;
        stats
    });
    let r = mesh_io::TopologyReport::of(&mesh);
    // Distinct vertices closer than float32 rounding of a CAD export would explain.
    let near_pairs = count_near_pairs(&mesh, PROBE_RELATIVE_TOLERANCE);
    if args.json {
        #[derive(serde::Serialize)]
        struct Out<'a> {
            file: String,
            #[serde(flatten)]
            report: &'a mesh_io::TopologyReport,
            /// Pairs of distinct vertices within `near_pair_relative_distance` × diagonal
            /// (counting stops at 1,000,000).
            num_near_vertex_pairs: usize,
            near_pair_relative_distance: f64,
            /// Present with --weld-tolerance: what the weld did before the report.
            #[serde(skip_serializing_if = "Option::is_none")]
            weld: Option<WeldStats>,
        }
        let out = Out {
            file: args.mesh.display().to_string(),
            report: &r,
            num_near_vertex_pairs: near_pairs,
            near_pair_relative_distance: PROBE_RELATIVE_TOLERANCE,
            weld,
        };
        crate::output::out!("{}", serde_json::to_string_pretty(&out).map_err(anyhow::Error::from)?);
        return Ok(());
    }
    let yes = |b: bool| if b { "yes" } else { "no" };
    crate::output::out!("{}", args.mesh.display());
    if let Some(w) = &weld {
        crate::output::out!(
            "  welded at {:e} × diagonal ({:.3e}): {} → {} vertices, {} degenerate triangles dropped",
            w.relative_tolerance,
            w.absolute_tolerance,
            w.vertices_before,
            w.vertices_after,
            w.degenerate_triangles_dropped
        );
    }
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
        Some(g) => crate::output::out!("  genus               {g}"),
        None => crate::output::out!("  genus               n/a (not closed, manifold and oriented)"),
    }
    crate::output::out!("  closed              {}", yes(r.is_closed));
    crate::output::out!("  manifold            {}", yes(r.is_manifold));
    crate::output::out!("  consistently oriented {}", yes(r.is_orientation_consistent));
    crate::output::out!("  signed volume       {:.9e}", r.signed_volume);
    crate::output::out!("  surface area        {:.9e}", r.surface_area);
    crate::output::out!("  bounding box        {:?} .. {:?}", r.bbox_min, r.bbox_max);
    let at_least = if near_pairs >= NEAR_PAIR_LIMIT { "at least " } else { "" };
    crate::output::out!(
        "  near vertex pairs   {at_least}{near_pairs} (distinct vertices within {PROBE_RELATIVE_TOLERANCE:e} × diagonal)"
    );
    if near_pairs > 0 && !r.is_closed {
        crate::output::out!(
            "hint: {at_least}{near_pairs} vertex pairs lie within {t:e} of the diagonal: try --weld-tolerance {t:e}",
            t = PROBE_RELATIVE_TOLERANCE
        );
    }
    if let Err(e) = mesh_io::check_f32_resolution(&mesh, &args.mesh) {
        crate::output::out!("note: {}. GLB / glTF output in this frame would be refused.", e.message);
    }
    Ok(())
}
