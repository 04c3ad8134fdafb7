//! The study's files: results.csv, hausdorff_vs_params.svg and .png, table.md and
//! budget.json, each written atomically.

use std::path::Path;

use crate::budget::Budget;
use crate::runs::Row;
use crate::StudyError;

fn write_text(path: &Path, text: &str) -> Result<(), StudyError> {
    mesh_io::atomic_write(path, |w| w.write_all(text.as_bytes()))?;
    Ok(())
}

/// Writes the study's files into `out` (which must exist).
///
/// # Errors
/// [`StudyError`] when a file cannot be written.
pub fn write(out: &Path, rows: &[Row], budget: &Budget, seed: u64, quick: bool) -> Result<(), StudyError> {
    write_csv(out, rows)?;
    write_plot(out, rows, quick)?;
    write_table(out, rows, budget, seed)?;
    write_budget(out, budget)
}

fn write_csv(out: &Path, rows: &[Row]) -> Result<(), StudyError> {
    let mut csv = String::from(
        "method,params,hausdorff_lo,hausdorff_hi,chamfer,train_seconds,steps,size,triangles,watertight,final_loss\n",
    );
    for r in rows {
        csv += &format!(
            "{},{},{:e},{:e},{:e},{:.3},{},{},{},{},{:e}\n",
            r.method,
            r.params,
            r.hausdorff_lo,
            r.hausdorff_hi,
            r.chamfer,
            r.train_seconds,
            r.steps,
            r.size,
            r.triangles,
            r.watertight,
            r.final_loss
        );
    }
    write_text(&out.join("results.csv"), &csv)?;

    Ok(())
}

fn write_plot(out: &Path, rows: &[Row], quick: bool) -> Result<(), StudyError> {
    let labels = [("voronoi", "Voronoi sites (3K)"), ("occnet", "OccNet MLP"), ("deepsdf", "DeepSDF MLP")];
    let series = labels
        .iter()
        .map(|(m, label)| {
            let mut pts: Vec<&Row> = rows.iter().filter(|r| r.method == *m && r.hausdorff_hi.is_finite()).collect();
            pts.sort_by_key(|r| r.params);
            plot::Series {
                name: label.to_string(),
                points: pts.iter().map(|r| (r.params as f64, 0.5 * (r.hausdorff_lo + r.hausdorff_hi))).collect(),
                band: Some(pts.iter().map(|r| (r.hausdorff_lo, r.hausdorff_hi)).collect()),
            }
        })
        .filter(|s| !s.points.is_empty())
        .collect();
    let chart = plot::Chart {
        title: format!(
            "Sphere r = 0.35: Hausdorff distance vs parameters ({})",
            if quick { "quick budget" } else { "full budget" }
        ),
        x_label: "parameters".into(),
        y_label: "Hausdorff distance (unit cube, certified)".into(),
        log_x: true,
        log_y: true,
        series,
    };
    chart.write_svg(&out.join("hausdorff_vs_params.svg")).map_err(|e| StudyError::Run(format!("plot: {e}")))?;
    chart.write_png(&out.join("hausdorff_vs_params.png")).map_err(|e| StudyError::Run(format!("plot: {e}")))?;

    Ok(())
}

fn write_table(out: &Path, rows: &[Row], budget: &Budget, seed: u64) -> Result<(), StudyError> {
    let mut md = String::new();
    md += &format!(
        "Sphere of radius 0.35 in the unit cube; budgets: Voronoi {} steps × 16,384 samples (default preset), MLPs {} \
         steps × {} samples (Adam, lr {} cosine to 1%), marching cubes at {}³; {} training samples; seed {}.\n\n",
        budget.voronoi_steps, budget.mlp_steps, budget.mlp_batch, budget.mlp_lr, budget.mc_res, budget.samples, seed
    );
    md += "| method | size | parameters | Hausdorff [lo, hi] | Chamfer L1 | triangles | watertight | train s |\n";
    md += "|---|---|---|---|---|---|---|---|\n";
    for r in rows {
        md += &format!(
            "| {} | {} | {} | [{:.3e}, {:.3e}] | {:.3e} | {} | {} | {:.1} |\n",
            r.method,
            r.size,
            r.params,
            r.hausdorff_lo,
            r.hausdorff_hi,
            r.chamfer,
            r.triangles,
            if r.watertight { "yes" } else { "no" },
            r.train_seconds
        );
    }
    md += "\nParameters needed to reach a Hausdorff distance (certified upper bound) at or below h:\n\n";
    md += "| h | Voronoi | OccNet | DeepSDF |\n|---|---|---|---|\n";
    for h in [0.1, 0.05, 0.02, 0.01, 0.005, 0.002, 0.001] {
        let need = |m: &str| {
            rows.iter()
                .filter(|r| r.method == m && r.hausdorff_hi <= h)
                .map(|r| r.params)
                .min()
                .map_or("not reached".to_string(), |p| p.to_string())
        };
        md += &format!("| {h} | {} | {} | {} |\n", need("voronoi"), need("occnet"), need("deepsdf"));
    }
    write_text(&out.join("table.md"), &md)
}

fn write_budget(out: &Path, budget: &Budget) -> Result<(), StudyError> {
    let budget_json = serde_json::to_string_pretty(&budget).map_err(|e| StudyError::Run(e.to_string()))?;
    write_text(&out.join("budget.json"), &budget_json)?;

    Ok(())
}
