//! `voronoi-fit eval REFERENCE PREDICTION [--json]`: reconstruction metrics of a predicted
//! mesh against a reference (the `metrics` crate; the main job's report uses the same
//! `metrics::evaluate`).

use std::path::PathBuf;

use metrics::{CertifiedOptions, EvalOptions, MetricsError, SurfaceOptions};

use crate::cli_error::CliError;
use crate::output::out;

#[derive(clap::Args)]
pub struct Args {
    /// Reference mesh: .obj, .stl, .ply, .off, .gltf or .glb.
    pub reference: PathBuf,
    /// Predicted mesh, same formats.
    pub prediction: PathBuf,
    /// Print the report as JSON (layout `format_version` 1, documented in crates/metrics/README.md).
    #[arg(long)]
    pub json: bool,
    /// Surface samples per mesh for Chamfer, F-score and normal consistency.
    #[arg(long, default_value_t = 100_000, value_name = "N")]
    pub samples: usize,
    /// Uniform samples for the volumetric IoU (0 skips it).
    #[arg(long, default_value_t = 100_000, value_name = "N")]
    pub iou_samples: usize,
    /// Seed of every sampler.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// F-score threshold τ as a fraction of the reference's bounding-box diagonal.
    #[arg(long, default_value_t = 0.003, value_name = "REL")]
    pub fscore_tau: f64,
    /// Largest width of the certified Hausdorff interval as a fraction of the bounding-box
    /// diagonal of both meshes.
    #[arg(long, default_value_t = 1e-6, value_name = "REL")]
    pub hausdorff_tol: f64,
    /// Skip the validity checks of the prediction (exact self-intersection test).
    #[arg(long)]
    pub no_validity: bool,
}

fn to_cli(e: MetricsError, args: &Args) -> CliError {
    let which = |mesh: &str| match mesh {
        "reference" => args.reference.display().to_string(),
        _ => args.prediction.display().to_string(),
    };
    match &e {
        MetricsError::Empty { mesh }
        | MetricsError::BadVertex { mesh, .. }
        | MetricsError::VertexOutOfRange { mesh, .. }
        | MetricsError::ZeroArea { mesh, .. } => CliError::input(format!("{}: {e}", which(mesh))),
        MetricsError::BadOption(_) => CliError::input(&e),
        MetricsError::Occupancy(_) => CliError::failure(&e),
    }
}

pub fn run(args: Args) -> Result<(), CliError> {
    let reference = mesh_io::read_mesh(&args.reference)?;
    let prediction = mesh_io::read_mesh(&args.prediction)?;
    let opts = EvalOptions {
        hausdorff: CertifiedOptions { rel_tolerance: args.hausdorff_tol, ..Default::default() },
        surface: SurfaceOptions { num_samples: args.samples, seed: args.seed, fscore_tau_rel: args.fscore_tau },
        iou_samples: Some(args.iou_samples),
        skip_validity: args.no_validity,
    };
    let r = metrics::evaluate(&reference, &prediction, &opts).map_err(|e| to_cli(e, &args))?;
    if args.json {
        #[derive(serde::Serialize)]
        struct Out<'a> {
            reference: String,
            prediction: String,
            #[serde(flatten)]
            report: &'a metrics::EvalReport,
        }
        let o = Out {
            reference: args.reference.display().to_string(),
            prediction: args.prediction.display().to_string(),
            report: &r,
        };
        out!("{}", serde_json::to_string_pretty(&o).map_err(anyhow::Error::from)?);
        return Ok(());
    }
    let h = &r.hausdorff;
    let s = &r.surface;
    out!("{} (prediction) against {} (reference)", args.prediction.display(), args.reference.display());
    out!("  Hausdorff, certified   [{:.9e}, {:.9e}]{}", h.lo, h.hi, if h.converged { "" } else { " (not converged)" });
    out!("  Hausdorff, libigl      {:.9e} (vertices only)", r.hausdorff_libigl);
    out!(
        "  Chamfer L1             {:.9e} (accuracy {:.6e}, completeness {:.6e})",
        s.chamfer_l1,
        s.accuracy,
        s.completeness
    );
    out!("  Chamfer L2             {:.9e}", s.chamfer_l2);
    out!(
        "  F-score at {:.4e}     {:.6} (precision {:.6}, recall {:.6})",
        s.fscore_tau,
        s.fscore,
        s.precision,
        s.recall
    );
    out!("  normal consistency     {:.6}", s.normal_consistency);
    match r.iou.as_ref().map(|i| i.iou) {
        Some(Some(iou)) => out!("  volumetric IoU         {iou:.6}"),
        Some(None) => out!("  volumetric IoU         n/a (no sample inside either mesh)"),
        None => out!("  volumetric IoU         skipped"),
    }
    if let Some(v) = &r.prediction_validity {
        let yes = |b: bool| if b { "yes" } else { "no" };
        out!(
            "  prediction             valid solid {}, closed {}, manifold {}, oriented {}, self-intersecting {}",
            yes(v.is_valid_solid),
            yes(v.is_closed),
            yes(v.is_manifold),
            yes(v.is_orientation_consistent),
            yes(v.self_intersecting)
        );
        let genus = v.genus.map_or("n/a".to_string(), |g| g.to_string());
        out!("                         components {}, genus {genus}", v.num_components);
    }
    out!("  time                   {:.3} s (Hausdorff {:.3} s)", r.seconds, h.seconds);
    Ok(())
}
