//! How a fit reports progress and is asked to stop: the CLI draws a progress bar and
//! turns Ctrl-C into [`Progress::should_stop`]; the Python package forwards to a callback.

use soft_voronoi::StepStats;

/// The stages of a fit, in order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Normalise the mesh into the unit cube.
    Load,
    /// Build the occupancy oracle (BVH, winding-number moments).
    Oracle,
    /// Sample and label the training pool.
    Sample,
    /// Train the sites.
    Train,
    /// Polish the trained sites onto the surface samples.
    Polish,
    /// Extract, check and map back the crust.
    Crust,
    /// Misclassification on fresh samples.
    Evaluate,
    /// Metrics against the input.
    Metrics,
}

impl Stage {
    /// The stage's key in the report's `timings_seconds`.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Load => "load",
            Stage::Oracle => "oracle",
            Stage::Sample => "sample",
            Stage::Train => "train",
            Stage::Polish => "polish",
            Stage::Crust => "crust",
            Stage::Evaluate => "evaluate",
            Stage::Metrics => "metrics",
        }
    }
}

/// Receives progress; every method has a default that does nothing.
pub trait Progress {
    /// A stage starts.
    fn stage(&mut self, _stage: Stage) {}
    /// Training starts (or resumes) at step `done` of `total`.
    fn train_start(&mut self, _done: usize, _total: usize) {}
    /// A training step finished.
    fn train_step(&mut self, _stats: &StepStats) {}
    /// Polled after every training step: `true` stops training after writing the
    /// checkpoint, and the fit returns [`crate::FitError::Interrupted`].
    fn should_stop(&mut self) -> bool {
        false
    }
    /// Training ended (finished or stopped).
    fn train_end(&mut self) {}
    /// A polish step finished: `done` of `total`, with its VoroLoss. Between steps the fit
    /// polls [`Progress::should_stop`] too.
    fn polish_step(&mut self, _done: usize, _total: usize, _loss: f64) {}
}

/// Progress that goes nowhere.
pub struct NoProgress;

impl Progress for NoProgress {}
