//! The jobs `voronoi-fit` runs, as a library driven by typed options: the main job for one
//! mesh, from a [`FitJob`] to the files on disk ([`fit_to_files`]), and the resumable batch
//! protocol over many meshes ([`batch`]), which `voronoi-fit batch` and the Python package's
//! Ray runner share.
//!
//! Nothing here parses arguments or prints: the front ends turn their flags into a
//! [`FitJob`] or [`batch::BatchOptions`], pass a [`fit::Progress`] or
//! [`batch::BatchProgress`] for their bars and an interrupt flag, and report the result.

pub mod batch;
mod error;
mod main_job;
pub mod occupancy_samples;

pub use error::{message_with_causes, Error};
pub use main_job::{fit_to_files, FitJob, Outputs, Written};
pub use occupancy_samples::OccupancySpec;
