//! `voronoi-fit study sphere [--quick] --out DIR`: the sphere study (crates/study) with a
//! progress bar and a closing summary.

use std::path::PathBuf;
use std::time::Instant;

use crate::cli_error::CliError;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The study: `sphere`.
    #[arg(value_parser = ["sphere"])]
    pub study: String,
    /// Output directory (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// Small sizes and budgets (under 2 minutes; what CI runs).
    #[arg(long)]
    pub quick: bool,
    /// Seeds of the samples and of every model, comma-separated (default: the budget's,
    /// 0,1,2 for the full study and 0,1 for --quick).
    #[arg(long, value_delimiter = ',')]
    pub seeds: Option<Vec<u64>>,
    /// Run only these parts, comma-separated: `voronoi`, `occnet`, `deepsdf`, `references`
    /// (default: all).
    #[arg(long, value_delimiter = ',', value_parser = ["voronoi", "occnet", "deepsdf", "references"])]
    pub only: Option<Vec<String>>,
    /// Voronoi site counts instead of the budget's, comma-separated (e.g. 1024,8192).
    #[arg(long, value_delimiter = ',')]
    pub sites: Option<Vec<usize>>,
    /// MLP sizes instead of the budget's, comma-separated WIDTHxDEPTH (e.g. 64x3,256x3).
    #[arg(long, value_delimiter = ',', value_parser = parse_size)]
    pub mlp_sizes: Option<Vec<(usize, usize)>>,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

fn parse_size(s: &str) -> Result<(usize, usize), String> {
    let bad = || format!("`{s}`: an MLP size is WIDTHxDEPTH with both in 1..=4096, e.g. 64x3");
    let (w, d) = s.split_once(['x', 'X', '×']).ok_or_else(bad)?;
    let (w, d): (usize, usize) = (w.trim().parse().map_err(|_| bad())?, d.trim().parse().map_err(|_| bad())?);
    if !(1..=4096).contains(&w) || !(1..=4096).contains(&d) {
        return Err(bad());
    }
    Ok((w, d))
}

struct Bar {
    bar: indicatif::ProgressBar,
    out: PathBuf,
}

impl study::StudyProgress for Bar {
    fn start(&mut self, label: &str) {
        self.bar.set_message(label.to_string());
    }
    fn done(&mut self, rows: &[study::Row]) {
        self.bar.inc(1);
        if let Some(r) = rows.last().filter(|r| r.is_failed()) {
            self.bar.suspend(|| eprintln!("voronoi-fit: {} {} (seed {}): {}", r.method, r.size, r.seed, r.convergence));
        }
        // Saved as it goes: an interrupted study keeps every finished run.
        if let Err(e) = study::write::write_csv(&self.out, rows) {
            self.bar.suspend(|| eprintln!("voronoi-fit: cannot save results.csv so far: {e}"));
        }
    }
}

pub fn run(args: Args) -> Result<(), CliError> {
    let t_all = Instant::now();
    let mut budget = if args.quick { study::Budget::quick() } else { study::Budget::full() };
    if let Some(seeds) = args.seeds.filter(|s| !s.is_empty()) {
        budget.seeds = seeds;
    }
    if let Some(sites) = args.sites {
        if let Some(&k) = sites.iter().find(|&&k| !(2..=1 << 20).contains(&k)) {
            return Err(CliError::input(format!("--sites {k}: every site count must be in 2..=1048576")));
        }
        budget.voronoi_sites = sites;
    }
    if let Some(sizes) = args.mlp_sizes {
        budget.mlp_sizes = sizes;
    }
    if let Some(only) = &args.only {
        let has = |p: &str| only.iter().any(|o| o == p);
        budget.voronoi = has("voronoi");
        budget.decoders.retain(|d| has(d));
        budget.references = has("references");
    }
    let meshes = args.out.join("meshes");
    std::fs::create_dir_all(&meshes)
        .map_err(|e| CliError::failure(format!("{}: cannot create the output directory ({e})", args.out.display())))?;
    let runs = study::num_units(&budget) as u64;
    let bar = if args.quiet { indicatif::ProgressBar::hidden() } else { indicatif::ProgressBar::new(runs) };
    bar.set_style(
        indicatif::ProgressStyle::with_template("study {bar:30} {pos}/{len} runs, {msg}, {elapsed} (ETA {eta})")
            .map_err(anyhow::Error::from)?,
    );
    let mut progress = Bar { bar, out: args.out.clone() };
    let rows = study::run(&budget, &meshes, &mut progress)?;
    progress.bar.finish_and_clear();
    let seconds = t_all.elapsed().as_secs_f64();
    study::write::write(&args.out, &rows, &budget, args.quick, seconds)?;
    let failed: Vec<String> =
        rows.iter().filter(|r| r.is_failed()).map(|r| format!("{} {} (seed {})", r.method, r.size, r.seed)).collect();
    let leaky = rows.iter().filter(|r| r.method == "voronoi" && !r.is_failed() && !r.watertight).count();
    crate::output::out!(
        "study sphere ({}): {} runs and references over seeds {:?} in {:.1} s; wrote {}/results.csv, summary.csv, \
         hausdorff_vs_params.svg/.png, table.md, budget.json and meshes/ (seed {}). Every Voronoi crust is watertight: \
         {}.",
        if args.quick { "quick" } else { "full" },
        rows.len(),
        budget.seeds,
        t_all.elapsed().as_secs_f64(),
        args.out.display(),
        budget.seeds[0],
        if leaky == 0 { "yes" } else { "NO" }
    );
    if !failed.is_empty() {
        return Err(CliError::failure(format!(
            "{} run(s) failed and are in the results as `failed` rows: {}",
            failed.len(),
            failed.join(", ")
        )));
    }
    Ok(())
}
