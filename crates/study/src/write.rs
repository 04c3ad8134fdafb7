//! The study's files: results.csv (every run), summary.csv (per method and size over the
//! seeds), hausdorff_vs_params.svg and .png, table.md and budget.json, each written
//! atomically.

use std::collections::BTreeMap;
use std::path::Path;

use serde::Serialize;

use crate::budget::Budget;
use crate::runs::Row;
use crate::StudyError;

/// Targets of the "parameters needed" table.
pub const TARGETS: [f64; 5] = [1e-2, 5e-3, 2e-3, 1e-3, 5e-4];

/// One (method, size) over its seeds.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    /// The method ([`Row::method`]).
    pub method: String,
    /// The size ([`Row::size`]).
    pub size: String,
    /// Parameters.
    pub params: usize,
    /// Runs (seeds).
    pub runs: usize,
    /// Median over the seeds of the certified interval's lower end.
    pub hausdorff_lo_median: f64,
    /// Median over the seeds of its upper end.
    pub hausdorff_hi_median: f64,
    /// Smallest upper end over the seeds.
    pub hausdorff_hi_min: f64,
    /// Largest upper end over the seeds.
    pub hausdorff_hi_max: f64,
    /// Lowest lower end over the seeds (the plot's band runs from it to `hausdorff_hi_max`).
    pub hausdorff_lo_min: f64,
    /// Median Chamfer distance over the seeds.
    pub chamfer_median: f64,
    /// Smallest Chamfer distance.
    pub chamfer_min: f64,
    /// Largest Chamfer distance.
    pub chamfer_max: f64,
    /// Median training steps (rounded).
    pub steps_median: usize,
    /// How the runs ended, e.g. `3 plateau` or `2 plateau, 1 capped`.
    pub convergence: String,
    /// Whether every run's surface is closed and manifold.
    pub all_watertight: bool,
    /// Median training wall time.
    pub train_seconds_median: f64,
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

/// Groups the rows by (method, size), in first-seen order.
pub fn summarise(rows: &[Row]) -> Vec<Summary> {
    let mut order: Vec<(String, String)> = Vec::new();
    let mut groups: BTreeMap<(String, String), Vec<&Row>> = BTreeMap::new();
    for r in rows {
        let key = (r.method.clone(), r.size.clone());
        if !groups.contains_key(&key) {
            order.push(key.clone());
        }
        groups.entry(key).or_default().push(r);
    }
    order
        .into_iter()
        .map(|key| {
            let g = &groups[&key];
            let col = |f: fn(&Row) -> f64| g.iter().map(|r| f(r)).collect::<Vec<f64>>();
            let his = col(|r| r.hausdorff_hi);
            let chamfers = col(|r| r.chamfer);
            let nan_max = |v: &[f64]| {
                v.iter().copied().fold(f64::NEG_INFINITY, |a, b| if b.is_nan() { f64::NAN } else { a.max(b) })
            };
            let nan_min =
                |v: &[f64]| v.iter().copied().fold(f64::INFINITY, |a, b| if b.is_nan() { f64::NAN } else { a.min(b) });
            let mut ends: BTreeMap<&str, usize> = BTreeMap::new();
            for r in g {
                *ends.entry(r.convergence.as_str()).or_default() += 1;
            }
            let steps = median(g.iter().map(|r| r.steps as f64).collect()).round() as usize;
            Summary {
                method: key.0.clone(),
                size: key.1.clone(),
                params: g[0].params,
                runs: g.len(),
                hausdorff_lo_median: median(col(|r| r.hausdorff_lo)),
                hausdorff_hi_median: median(his.clone()),
                hausdorff_hi_min: nan_min(&his),
                hausdorff_hi_max: nan_max(&his),
                hausdorff_lo_min: nan_min(&col(|r| r.hausdorff_lo)),
                chamfer_median: median(chamfers.clone()),
                chamfer_min: nan_min(&chamfers),
                chamfer_max: nan_max(&chamfers),
                steps_median: steps,
                convergence: ends.iter().map(|(k, n)| format!("{n} {k}")).collect::<Vec<_>>().join(", "),
                all_watertight: g.iter().all(|r| r.watertight),
                train_seconds_median: median(col(|r| r.train_seconds)),
            }
        })
        .collect()
}

/// Smallest parameter count of `method` whose every seed reaches `h` (certified upper end).
pub fn params_needed(summaries: &[Summary], method: &str, h: f64) -> Option<usize> {
    summaries.iter().filter(|s| s.method == method && s.hausdorff_hi_max <= h).map(|s| s.params).min()
}

fn write_text(path: &Path, text: &str) -> Result<(), StudyError> {
    mesh_io::atomic_write(path, |w| w.write_all(text.as_bytes()))?;
    Ok(())
}

/// Writes the study's files into `out` (which must exist); `seconds`: the study's wall
/// time, stated in table.md and budget.json.
///
/// # Errors
/// [`StudyError`] when a file cannot be written.
pub fn write(out: &Path, rows: &[Row], budget: &Budget, quick: bool, seconds: f64) -> Result<(), StudyError> {
    let summaries = summarise(rows);
    write_csv(out, rows)?;
    write_summary_csv(out, &summaries)?;
    write_plot(out, &summaries, budget, quick)?;
    write_table(out, &summaries, budget, seconds)?;
    write_budget(out, budget, seconds)
}

/// Writes results.csv (every row so far) atomically: the CLI calls it after each run, so
/// an interrupted study keeps what it finished.
///
/// # Errors
/// [`StudyError`] when the file cannot be written.
pub fn write_csv(out: &Path, rows: &[Row]) -> Result<(), StudyError> {
    let mut csv = String::from(
        "method,params,hausdorff_lo,hausdorff_hi,chamfer,train_seconds,steps,size,seed,triangles,watertight,\
         final_loss,convergence,total_seconds\n",
    );
    for r in rows {
        csv += &format!(
            "{},{},{:e},{:e},{:e},{:.3},{},{},{},{},{},{:e},{},{:.3}\n",
            r.method,
            r.params,
            r.hausdorff_lo,
            r.hausdorff_hi,
            r.chamfer,
            r.train_seconds,
            r.steps,
            r.size,
            r.seed,
            r.triangles,
            r.watertight,
            r.final_loss,
            r.convergence.replace([',', '\n'], ";"),
            r.total_seconds
        );
    }
    write_text(&out.join("results.csv"), &csv)
}

fn write_summary_csv(out: &Path, summaries: &[Summary]) -> Result<(), StudyError> {
    let mut csv = String::from(
        "method,size,params,runs,hausdorff_lo_median,hausdorff_hi_median,hausdorff_hi_min,hausdorff_hi_max,\
         chamfer_median,chamfer_min,chamfer_max,steps_median,convergence,all_watertight,train_seconds_median\n",
    );
    for s in summaries {
        csv += &format!(
            "{},{},{},{},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{},{},{},{:.3}\n",
            s.method,
            s.size,
            s.params,
            s.runs,
            s.hausdorff_lo_median,
            s.hausdorff_hi_median,
            s.hausdorff_hi_min,
            s.hausdorff_hi_max,
            s.chamfer_median,
            s.chamfer_min,
            s.chamfer_max,
            s.steps_median,
            s.convergence.replace(',', ";"),
            s.all_watertight,
            s.train_seconds_median
        );
    }
    write_text(&out.join("summary.csv"), &csv)
}

fn write_plot(out: &Path, summaries: &[Summary], budget: &Budget, quick: bool) -> Result<(), StudyError> {
    let labels = [
        ("voronoi", "Voronoi sites, main job (3K)"),
        ("occnet", "OccNet MLP"),
        ("deepsdf", "DeepSDF MLP (SAL init)"),
        ("construction", "K-site construction, no training"),
    ];
    let mut series: Vec<plot::Series> = labels
        .iter()
        .map(|(m, label)| {
            let mut pts: Vec<&Summary> =
                summaries.iter().filter(|s| s.method == *m && s.hausdorff_hi_median.is_finite()).collect();
            pts.sort_by_key(|s| s.params);
            let spread = *m != "construction";
            plot::Series {
                name: label.to_string(),
                points: pts.iter().map(|s| (s.params as f64, s.hausdorff_hi_median)).collect(),
                band: spread.then(|| pts.iter().map(|s| (s.hausdorff_lo_min, s.hausdorff_hi_max)).collect()),
            }
        })
        .filter(|s| !s.points.is_empty())
        .collect();
    let xs: Vec<f64> = summaries.iter().filter(|s| s.params > 0).map(|s| s.params as f64).collect();
    if let Some(floor) = summaries.iter().find(|s| s.method == "mc_floor" && s.hausdorff_lo_median > 0.0) {
        let (lo, hi) = (xs.iter().copied().fold(f64::INFINITY, f64::min), xs.iter().copied().fold(0.0, f64::max));
        if lo < hi {
            series.push(plot::Series {
                name: format!("marching-cubes floor ({}³ grid of the exact SDF, lower end)", budget.mc_res),
                points: vec![(lo, floor.hausdorff_lo_median), (hi, floor.hausdorff_lo_median)],
                band: None,
            });
        }
    }
    if series.is_empty() {
        // Nothing with a parameter count ran (only the floor): no plot.
        return Ok(());
    }
    let chart = plot::Chart {
        title: format!(
            "Sphere r = 0.35: Hausdorff distance vs parameters, median and range over {} seeds ({})",
            budget.seeds.len(),
            if quick { "quick budget" } else { "full budget" }
        ),
        x_label: "parameters".into(),
        y_label: "Hausdorff distance (unit cube, certified upper end)".into(),
        log_x: true,
        log_y: true,
        series,
    };
    chart.write_svg(&out.join("hausdorff_vs_params.svg")).map_err(|e| StudyError::Run(format!("plot: {e}")))?;
    chart.write_png(&out.join("hausdorff_vs_params.png")).map_err(|e| StudyError::Run(format!("plot: {e}")))?;
    Ok(())
}

fn fmt_need(n: Option<usize>) -> String {
    n.map_or("not reached".into(), |p| p.to_string())
}

fn write_table(out: &Path, summaries: &[Summary], budget: &Budget, seconds: f64) -> Result<(), StudyError> {
    let rule = &budget.mlp_plateau;
    let mut md = String::new();
    let selection = format!(
        " on its cosine schedule, keeping its best iterate by a fixed evaluation batch's loss (measured every {} \
         steps); `flattened` when the last tenth's mean loss is not below the tenth before's by more than 1% or \
         two standard errors{}",
        soft_voronoi::TrainConfig::default_for(8192).select_every,
        if budget.voronoi_max_doublings == 0 {
            String::new()
        } else {
            format!("; steps doubled while not flattened, up to {}×", 1usize << budget.voronoi_max_doublings)
        }
    );
    md += &format!(
        "Sphere of radius 0.35 in the unit cube; seeds {:?}; {} training samples per seed for every method (half \
         uniform, half near the surface). Voronoi: the main job (`fit::fit`, default settings) on an icosphere \
         ({} subdivisions, vertices on the sphere), {} steps{}. MLPs: Adam from lr {} at batch {}, ×{} at each plateau (windows of {} steps, {}% improvement, \
         patience {}), stopped at the plateau after {} reductions, at least {} and at most {} steps; DeepSDF from \
         SAL's geometric initialisation; marching cubes at {}³. Wall time of this run: {:.0} s on {} threads.\n\n",
        budget.seeds,
        budget.samples,
        budget.icosphere_subdivisions,
        budget.voronoi_steps.map_or_else(
            || format!("{} (the default)", soft_voronoi::TrainConfig::default_for(8192).steps),
            |s| s.to_string(),
        ),
        selection,
        budget.mlp_lr,
        budget.mlp_batch,
        rule.factor,
        rule.window,
        100.0 * rule.min_improvement,
        rule.patience,
        rule.reductions,
        rule.min_steps,
        rule.max_steps,
        budget.mc_res,
        seconds,
        rayon::current_num_threads(),
    );
    md += "Certified Hausdorff distance to the sphere (median over the seeds of the interval's ends, and the range \
           of the upper end) and Chamfer L1 (median [range]):\n\n";
    md += "| method | size | parameters | Hausdorff [lo, hi] (median) | hi over seeds | Chamfer L1 | steps (median) \
           | how training ended | watertight | train s (median) |\n";
    md += "|---|---|---|---|---|---|---|---|---|---|\n";
    for s in summaries {
        md += &format!(
            "| {} | {} | {} | [{:.3e}, {:.3e}] | {:.3e} – {:.3e} | {:.3e} [{:.2e}, {:.2e}] | {} | {} | {} | {:.1} |\n",
            s.method,
            s.size,
            s.params,
            s.hausdorff_lo_median,
            s.hausdorff_hi_median,
            s.hausdorff_hi_min,
            s.hausdorff_hi_max,
            s.chamfer_median,
            s.chamfer_min,
            s.chamfer_max,
            s.steps_median,
            s.convergence,
            if s.all_watertight { "yes" } else { "no" },
            s.train_seconds_median
        );
    }
    md += "\nParameters needed to reach a certified Hausdorff distance h under every seed (the smallest size \
           run that does; sizes double for Voronoi and quadruple for the MLPs, so each figure is good to that \
           factor), and the ratio to Voronoi's:\n\n";
    md += "| h | Voronoi (main job) | construction | OccNet | DeepSDF | OccNet / Voronoi | DeepSDF / Voronoi |\n";
    md += "|---|---|---|---|---|---|---|\n";
    for h in TARGETS {
        let v = params_needed(summaries, "voronoi", h);
        let c = params_needed(summaries, "construction", h);
        let o = params_needed(summaries, "occnet", h);
        let d = params_needed(summaries, "deepsdf", h);
        let ratio = |m: Option<usize>| match (m, v) {
            (Some(m), Some(v)) => format!("{:.1}", m as f64 / v as f64),
            (None, Some(_)) => "MLP not reached".into(),
            (Some(_), None) => "Voronoi not reached".into(),
            (None, None) => "-".into(),
        };
        md += &format!(
            "| {h:e} | {} | {} | {} | {} | {} | {} |\n",
            fmt_need(v),
            fmt_need(c),
            fmt_need(o),
            fmt_need(d),
            ratio(o),
            ratio(d)
        );
    }
    let mut worse = Vec::new();
    for m in ["voronoi", "occnet", "deepsdf", "construction"] {
        let mut g: Vec<&Summary> = summaries.iter().filter(|s| s.method == m).collect();
        g.sort_by_key(|s| s.params);
        for w in g.windows(2) {
            if w[1].hausdorff_hi_median > w[0].hausdorff_hi_median {
                worse.push(format!(
                    "{m} {} → {} ({:.3e} → {:.3e})",
                    w[0].size, w[1].size, w[0].hausdorff_hi_median, w[1].hausdorff_hi_median
                ));
            }
        }
    }
    md += "\nWhere the median error grows with size: ";
    md += &if worse.is_empty() { "nowhere.".to_string() } else { worse.join("; ") + "." };
    md += "\n";
    write_text(&out.join("table.md"), &md)
}

fn write_budget(out: &Path, budget: &Budget, seconds: f64) -> Result<(), StudyError> {
    #[derive(Serialize)]
    struct Written<'a> {
        budget: &'a Budget,
        wall_seconds: f64,
        threads: usize,
    }
    let w = Written { budget, wall_seconds: seconds, threads: rayon::current_num_threads() };
    let json = serde_json::to_string_pretty(&w).map_err(|e| StudyError::Run(e.to_string()))?;
    write_text(&out.join("budget.json"), &json)
}
