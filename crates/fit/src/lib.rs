//! The main job of voronoi-fit as a library call: [`fit`] takes a triangle mesh and a
//! [`FitConfig`] and returns the trained sites, the checked crust in the input's frame and
//! a serialisable [`FitReport`]. The CLI (`voronoi-fit MESH`), the sphere study, batch
//! runs and the Python package all call it.
//!
//! Stages (each timed in the report): drop unreferenced vertices and normalise into the
//! unit cube ([`data`]); build the occupancy oracle; sample and label the training pool by
//! the workspace's one inside rule ([`occupancy::Config::is_inside_winding`]), or around a
//! thin shell when the mesh encloses no volume ([`target`]); train the
//! sites with the soft-Voronoi ([`soft_voronoi::Trainer`]), checkpointing as asked; extract
//! and check the crust, map it back and round it as the output stores it, checked again
//! ([`crust_of`]); measure the
//! misclassification on fresh samples and the `eval` metrics against the input.
//!
//! # Example
//! ```no_run
//! let mesh = mesh_io::read_mesh(std::path::Path::new("bunny.obj"))?;
//! let config = fit::FitConfig::new("bunny.obj", 8192);
//! let out = fit::fit(&mesh, &config, &mut fit::NoProgress)?;
//! println!("{} crust triangles", out.crust.triangles.len());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod carve;
pub mod config;
pub mod crust_step;
pub mod data;
pub mod error;
pub mod grading;
pub mod grow;
pub mod guard;
pub mod options;
pub mod progress;
mod refine;
pub mod report;
mod run;
pub mod target;

pub use config::{
    Checkpointing, EvalSampling, FitConfig, Sampling, SolidRule, DEFAULT_CARVE, DEFAULT_EVAL_SAMPLES, DEFAULT_SITES,
    MARGIN, TRY_ALIGNMENT_WEIGHT,
};
pub use crust_step::{crust_of, CheckedCrust};
pub use error::{FitError, MeshFault};
pub use grow::{fit_to_accuracy, AccuracyGoal, DEFAULT_MAX_SITES};
pub use options::FitOptions;
pub use progress::{NoProgress, Progress, Stage};
pub use report::FitReport;
pub use report::{CHOSEN_AFTER_EMPTY_WINDING, CHOSEN_FOR_LARGE_CAPS};
pub use run::{fit, FitOutput};
