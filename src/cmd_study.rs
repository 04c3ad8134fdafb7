//! `voronoi-fit study sphere [--quick] --out DIR`: the arguments of the sphere study, run
//! by `study::run_study` (crates/study), with a progress bar and a closing summary.

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

/// The study's progress on the terminal: a bar (none with `--quiet`), failed runs and
/// warnings above it.
struct Bar {
    bar: indicatif::ProgressBar,
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
    }
    fn warning(&mut self, message: &str) {
        self.bar.suspend(|| eprintln!("voronoi-fit: {message}"));
    }
}

pub fn run(args: Args) -> Result<(), CliError> {
    let t_all = Instant::now();
    let options = study::StudyOptions {
        quick: args.quick,
        seeds: args.seeds,
        only: args.only,
        sites: args.sites,
        mlp_sizes: args.mlp_sizes,
    };
    let budget = options.budget()?;
    let runs = study::num_units(&budget) as u64;
    let bar = if args.quiet { indicatif::ProgressBar::hidden() } else { indicatif::ProgressBar::new(runs) };
    bar.set_style(
        indicatif::ProgressStyle::with_template("study {bar:30} {pos}/{len} runs, {msg}, {elapsed} (ETA {eta})")
            .map_err(anyhow::Error::from)?,
    );
    let mut progress = Bar { bar };
    let outcome = study::run_study(&args.out, &budget, args.quick, &mut progress);
    progress.bar.finish_and_clear();
    let outcome = outcome?;
    let failed = outcome.failed();
    crate::output::out!(
        "study sphere ({}): {} runs and references over seeds {:?} in {:.1} s; wrote {}/results.csv, summary.csv, \
         hausdorff_vs_params.svg/.png, table.md, budget.json and meshes/ (seed {}). Every Voronoi crust is watertight: \
         {}.",
        if args.quick { "quick" } else { "full" },
        outcome.rows.len(),
        budget.seeds,
        t_all.elapsed().as_secs_f64(),
        args.out.display(),
        budget.seeds[0],
        if outcome.leaky_crusts() == 0 { "yes" } else { "NO" }
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
