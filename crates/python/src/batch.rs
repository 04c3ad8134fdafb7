//! The batch protocol (`jobs::batch`, as `voronoi-fit batch` runs it) for the Ray runner,
//! `voronoi_fit.cluster`: plan the jobs of a manifest, check for a finished result, fit
//! one mesh into its work folder, publish it by rename, write `summary.csv`. The batch's
//! options cross as JSON (`jobs::batch::BatchOptions`).

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use jobs::batch::{BatchOptions, Job, Published, SummaryRow};
use pyo3::prelude::*;

use crate::{failure, input_error};

fn options(batch_json: &str) -> PyResult<BatchOptions> {
    serde_json::from_str(batch_json).map_err(|e| input_error(format!("batch options: {e}")))
}

fn job(input: &str, name: &str) -> Job {
    Job { input: PathBuf::from(input), name: name.to_string() }
}

fn to_py(e: jobs::Error) -> PyErr {
    let message = jobs::message_with_causes(&e);
    if e.is_input_fault() {
        input_error(message)
    } else {
        failure(message)
    }
}

/// The jobs of the inputs (mesh files, folders, `@LIST` files), in order and without
/// repeats: (input path, folder name) pairs, named as `voronoi-fit batch` names them.
#[pyfunction]
pub fn batch_plan(inputs: Vec<String>) -> PyResult<Vec<(String, String)>> {
    let plan = jobs::batch::plan(&inputs).map_err(to_py)?;
    Ok(plan.into_iter().map(|j| (j.input.display().to_string(), j.name)).collect())
}

/// Whether `OUT/NAME/` already holds this mesh's result made with these options (a rerun
/// skips it). Reads the input to hash it.
#[pyfunction]
pub fn batch_finished(py: Python<'_>, batch_json: &str, input: &str, name: &str) -> PyResult<bool> {
    let options = options(batch_json)?;
    let job = job(input, name);
    py.allow_threads(|| {
        let prov = jobs::batch::provenance(&job, &options)?;
        Ok(jobs::batch::is_finished(&options.out.join(name), name, &prov))
    })
    .map_err(to_py)
}

/// Fits one mesh into the work folder `work` (created if needed): `batch.json`, the crust,
/// sites file, picture and report (`jobs::fit_to_files`), continuing from the folder's
/// checkpoint when `resume`. Raises `InputError` when the mesh or options are at fault.
#[pyfunction]
#[pyo3(signature = (batch_json, input, name, work, resume=false))]
pub fn batch_fit_into(
    py: Python<'_>,
    batch_json: &str,
    input: &str,
    name: &str,
    work: &str,
    resume: bool,
) -> PyResult<()> {
    let options = options(batch_json)?;
    let job = job(input, name);
    // A Ray task is stopped by ending its worker: nothing sets the flag.
    let never = AtomicBool::new(false);
    py.allow_threads(|| {
        let prov = jobs::batch::provenance(&job, &options)?;
        jobs::batch::fit_into(&job, &options, &prov, Path::new(work), resume, &never)
    })
    .map_err(to_py)
}

/// Publishes the work folder as `OUT/NAME/` by one rename (`jobs::batch::publish`; an
/// older result in the way is moved to `aside` and removed). Returns False when another
/// attempt had already published the same result (this work folder is then removed).
#[pyfunction]
pub fn batch_publish(
    py: Python<'_>,
    batch_json: &str,
    input: &str,
    name: &str,
    work: &str,
    aside: &str,
) -> PyResult<bool> {
    let options = options(batch_json)?;
    let job = job(input, name);
    py.allow_threads(|| {
        let prov = jobs::batch::provenance(&job, &options)?;
        jobs::batch::publish(Path::new(work), &options.out.join(name), Path::new(aside), &prov)
    })
    .map(|p| p == Published::Moved)
    .map_err(to_py)
}

/// Writes `OUT/summary.csv` atomically: rows as JSON (`jobs::batch::SummaryRow`: job,
/// status, error, seconds, finished, extra), figures from each finished folder's report,
/// then the runner's `extra_columns`.
#[pyfunction]
pub fn batch_write_summary(py: Python<'_>, out: &str, rows_json: &str, extra_columns: Vec<String>) -> PyResult<()> {
    let rows: Vec<SummaryRow> =
        serde_json::from_str(rows_json).map_err(|e| input_error(format!("summary rows: {e}")))?;
    py.allow_threads(|| jobs::batch::write_summary_rows(Path::new(out), &rows, &extra_columns)).map_err(to_py)
}
