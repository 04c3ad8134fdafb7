//! The `study sphere` command end to end: options over a [`Budget`], the output folder,
//! results.csv saved after every run (an interrupted study keeps what it finished), and
//! the study's files at the end.

use std::path::Path;
use std::time::Instant;

use crate::budget::Budget;
use crate::runs::{run, Row, StudyProgress};
use crate::{write, StudyError};

/// Which study and what to change of its [`Budget`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StudyOptions {
    /// [`Budget::quick`] (small sizes and budgets) instead of [`Budget::full`].
    pub quick: bool,
    /// Seeds instead of the budget's (`None` or empty: the budget's).
    pub seeds: Option<Vec<u64>>,
    /// Only these parts: `voronoi`, `occnet`, `deepsdf`, `references` (`None`: all).
    pub only: Option<Vec<String>>,
    /// Voronoi site counts instead of the budget's (each in 2..=1048576).
    pub sites: Option<Vec<usize>>,
    /// MLP (width, depth) sizes instead of the budget's.
    pub mlp_sizes: Option<Vec<(usize, usize)>>,
}

impl StudyOptions {
    /// The budget these options give.
    ///
    /// # Errors
    /// [`StudyError::Options`] for a site count out of range (named by its `--sites` flag).
    pub fn budget(&self) -> Result<Budget, StudyError> {
        let mut budget = if self.quick { Budget::quick() } else { Budget::full() };
        if let Some(seeds) = self.seeds.clone().filter(|s| !s.is_empty()) {
            budget.seeds = seeds;
        }
        if let Some(sites) = &self.sites {
            if let Some(&k) = sites.iter().find(|&&k| !(2..=1 << 20).contains(&k)) {
                return Err(StudyError::Options(format!("--sites {k}: every site count must be in 2..=1048576")));
            }
            budget.voronoi_sites = sites.clone();
        }
        if let Some(sizes) = &self.mlp_sizes {
            budget.mlp_sizes = sizes.clone();
        }
        if let Some(only) = &self.only {
            let has = |p: &str| only.iter().any(|o| o == p);
            budget.voronoi = has("voronoi");
            budget.decoders.retain(|d| has(d));
            budget.references = has("references");
        }
        Ok(budget)
    }
}

/// What [`run_study`] did.
#[derive(Clone, Debug)]
pub struct StudyOutcome {
    /// Every run and reference, in run order (also in results.csv).
    pub rows: Vec<Row>,
    /// The budget run.
    pub budget: Budget,
    /// Wall seconds of the study (stated in table.md and budget.json).
    pub seconds: f64,
}

impl StudyOutcome {
    /// The failed runs, as `method size (seed N)`.
    pub fn failed(&self) -> Vec<String> {
        self.rows
            .iter()
            .filter(|r| r.is_failed())
            .map(|r| format!("{} {} (seed {})", r.method, r.size, r.seed))
            .collect()
    }

    /// Voronoi crusts that are not watertight (0 when the construction holds).
    pub fn leaky_crusts(&self) -> usize {
        self.rows.iter().filter(|r| r.method == "voronoi" && !r.is_failed() && !r.watertight).count()
    }
}

/// Runs the study of `budget` into the folder `out` (created if missing; [`num_units`](crate::num_units)
/// progress units): the first
/// seed's surfaces in `out/meshes/`, results.csv after every run, then results.csv,
/// summary.csv, hausdorff_vs_params.svg/.png, table.md and budget.json
/// ([`write::write`]). A results.csv that cannot be saved along the way is a
/// [`StudyProgress::warning`], not an error.
///
/// # Errors
/// [`StudyError::CreateDir`] when the folder cannot be made; [`StudyError::Write`] when a
/// file cannot be written.
pub fn run_study(
    out: &Path,
    budget: &Budget,
    quick: bool,
    progress: &mut dyn StudyProgress,
) -> Result<StudyOutcome, StudyError> {
    let started = Instant::now();
    let meshes = out.join("meshes");
    std::fs::create_dir_all(&meshes)
        .map_err(|e| StudyError::CreateDir { path: out.to_path_buf(), message: e.to_string() })?;
    let rows = run(budget, &meshes, &mut Saving { inner: progress, out })?;
    let seconds = started.elapsed().as_secs_f64();
    write::write(out, &rows, budget, quick, seconds)?;
    Ok(StudyOutcome { rows, budget: budget.clone(), seconds })
}

/// Passes the progress on and saves results.csv after every run.
struct Saving<'a> {
    inner: &'a mut dyn StudyProgress,
    out: &'a Path,
}

impl StudyProgress for Saving<'_> {
    fn start(&mut self, label: &str) {
        self.inner.start(label);
    }

    fn done(&mut self, rows: &[Row]) {
        self.inner.done(rows);
        if let Err(e) = write::write_csv(self.out, rows) {
            self.inner.warning(&format!("cannot save results.csv so far: {e}"));
        }
    }

    fn warning(&mut self, message: &str) {
        self.inner.warning(message);
    }
}
