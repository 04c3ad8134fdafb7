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
    /// Seed of the samples and of every model.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

struct Bar(indicatif::ProgressBar);

impl study::StudyProgress for Bar {
    fn start(&mut self, label: &str) {
        self.0.set_message(label.to_string());
    }
    fn done(&mut self) {
        self.0.inc(1);
    }
}

pub fn run(args: Args) -> Result<(), CliError> {
    let t_all = Instant::now();
    let budget = if args.quick { study::Budget::quick() } else { study::Budget::full() };
    let meshes = args.out.join("meshes");
    std::fs::create_dir_all(&meshes)
        .map_err(|e| CliError::failure(format!("{}: cannot create the output directory ({e})", args.out.display())))?;
    let runs = budget.num_runs() as u64;
    let bar = if args.quiet { indicatif::ProgressBar::hidden() } else { indicatif::ProgressBar::new(runs) };
    bar.set_style(
        indicatif::ProgressStyle::with_template("study {bar:30} {pos}/{len} runs, {msg}, {elapsed} (ETA {eta})")
            .map_err(anyhow::Error::from)?,
    );
    let mut progress = Bar(bar);
    let rows = study::run(&budget, args.seed, &meshes, &mut progress)?;
    progress.0.finish_and_clear();
    study::write::write(&args.out, &rows, &budget, args.seed, args.quick)?;
    let leaky = rows.iter().filter(|r| r.method == "voronoi" && !r.watertight).count();
    crate::output::out!(
        "study sphere ({}): {} runs in {:.1} s; wrote {}/results.csv, hausdorff_vs_params.svg/.png, table.md and \
         meshes/. Every Voronoi crust is watertight: {}.",
        if args.quick { "quick" } else { "full" },
        rows.len(),
        t_all.elapsed().as_secs_f64(),
        args.out.display(),
        if leaky == 0 { "yes" } else { "NO" }
    );
    Ok(())
}
