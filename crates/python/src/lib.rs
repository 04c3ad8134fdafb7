//! `voronoi_fit._native`: the Python package's native half. Every function calls the same
//! library code as the CLI (`fit::fit` through `fit::FitOptions`, `occupancy::MeshOracle`,
//! `delaunay3`, `crust`, `metrics`, `viewer`, and `jobs`' batch protocol for the Ray runner)
//! and releases the GIL while it works.
//!
//! Arrays cross the boundary as little-endian bytes (`float64`, `uint32`, `uint8`), which
//! the pure-Python half (`python/voronoi_fit/__init__.py`) makes from and turns back into
//! numpy arrays with one copy each way. No rust-numpy: it pins its own ndarray and PyO3
//! versions and adds build time for what is a memcpy here.
//!
//! Errors: `InputError` (a `ValueError`) when the input is at fault, carrying the CLI's
//! message; `Error` (a `RuntimeError`) otherwise; an exception raised by the progress
//! callback, or Ctrl-C (`KeyboardInterrupt`), stops the fit at the next step and is
//! raised as it is.

mod batch;

use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyBytes;

use ::fit::{FitOptions, Progress, Stage};
use mesh_io::TriMesh;
use soft_voronoi::StepStats;

create_exception!(
    _native,
    InputError,
    PyValueError,
    "The input (a mesh, an array, an option) is unusable; the message says why and how to fix it."
);
create_exception!(_native, Error, PyRuntimeError, "A failure that is not the input's fault.");

pub(crate) fn input_error(m: impl std::fmt::Display) -> PyErr {
    InputError::new_err(m.to_string())
}

pub(crate) fn failure(m: impl std::fmt::Display) -> PyErr {
    Error::new_err(m.to_string())
}

/// n×3 float64 rows from little-endian bytes.
fn rows_f64(bytes: &[u8], what: &str) -> PyResult<Vec<[f64; 3]>> {
    if !bytes.len().is_multiple_of(24) {
        return Err(input_error(format!(
            "{what}: {} bytes is not a whole number of (x, y, z) float64 rows",
            bytes.len()
        )));
    }
    let v: Vec<[f64; 3]> = bytes
        .chunks_exact(24)
        .map(|c| [0, 1, 2].map(|i| f64::from_le_bytes(c[8 * i..8 * i + 8].try_into().unwrap_or([0; 8]))))
        .collect();
    if let Some(i) = v.iter().position(|p| !p.iter().all(|x| x.is_finite())) {
        return Err(input_error(format!("{what}: row {i} is not finite ({:?}); remove or fix it", v[i])));
    }
    Ok(v)
}

/// n×3 uint32 rows from little-endian bytes.
fn rows_u32(bytes: &[u8], what: &str) -> PyResult<Vec<[u32; 3]>> {
    if !bytes.len().is_multiple_of(12) {
        return Err(input_error(format!("{what}: {} bytes is not a whole number of uint32 triples", bytes.len())));
    }
    Ok(bytes
        .chunks_exact(12)
        .map(|c| [0, 1, 2].map(|i| u32::from_le_bytes(c[4 * i..4 * i + 4].try_into().unwrap_or([0; 4]))))
        .collect())
}

fn mesh(v: &[u8], f: &[u8], what: &str) -> PyResult<TriMesh> {
    let positions = rows_f64(v, &format!("{what} vertices"))?;
    let triangles = rows_u32(f, &format!("{what} faces"))?;
    if let Some((i, t)) = triangles.iter().enumerate().find(|(_, t)| t.iter().any(|&j| j as usize >= positions.len())) {
        return Err(input_error(format!(
            "{what} faces: face {i} {t:?} refers to a vertex beyond the {} given (indices are 0-based)",
            positions.len()
        )));
    }
    Ok(TriMesh { positions, triangles })
}

fn f64_bytes<'py, const N: usize>(py: Python<'py>, rows: &[[f64; N]]) -> Bound<'py, PyBytes> {
    let mut out = Vec::with_capacity(rows.len() * N * 8);
    rows.iter().flatten().for_each(|x| out.extend_from_slice(&x.to_le_bytes()));
    PyBytes::new(py, &out)
}

fn u32_bytes<'py, const N: usize>(py: Python<'py>, rows: &[[u32; N]]) -> Bound<'py, PyBytes> {
    let mut out = Vec::with_capacity(rows.len() * N * 4);
    rows.iter().flatten().for_each(|x| out.extend_from_slice(&x.to_le_bytes()));
    PyBytes::new(py, &out)
}

fn scalar_bytes<'py>(py: Python<'py>, xs: &[f64]) -> Bound<'py, PyBytes> {
    let mut out = Vec::with_capacity(xs.len() * 8);
    xs.iter().for_each(|x| out.extend_from_slice(&x.to_le_bytes()));
    PyBytes::new(py, &out)
}

type MeshBytes<'py> = (Bound<'py, PyBytes>, Bound<'py, PyBytes>);

/// Reads a mesh file as the CLI does (OBJ, STL, PLY, OFF, glTF, GLB; exact welding):
/// (vertices, faces) as bytes.
#[pyfunction]
fn load_mesh<'py>(py: Python<'py>, path: &str) -> PyResult<MeshBytes<'py>> {
    let m = py.allow_threads(|| mesh_io::read_mesh(std::path::Path::new(path))).map_err(|e| {
        if e.kind == mesh_io::ErrorKind::Write {
            failure(e)
        } else {
            input_error(e)
        }
    })?;
    Ok((f64_bytes(py, &m.positions), u32_bytes(py, &m.triangles)))
}

/// Forwards the fit's progress to a Python callable `callback(stage, step, steps, loss)`
/// and stops the fit when it raises or when Ctrl-C arrives.
struct PyProgress {
    callback: Option<Py<PyAny>>,
    error: Option<PyErr>,
    steps: usize,
}

impl PyProgress {
    fn call(&mut self, stage: &str, step: usize, loss: f64) {
        if self.error.is_some() {
            return;
        }
        Python::with_gil(|py| {
            if let Err(e) = py.check_signals() {
                self.error = Some(e);
            } else if let Some(cb) = &self.callback {
                if let Err(e) = cb.call1(py, (stage, step, self.steps, loss)) {
                    self.error = Some(e);
                }
            }
        });
    }
}

impl Progress for PyProgress {
    fn stage(&mut self, stage: Stage) {
        self.call(stage.name(), 0, f64::NAN);
    }
    fn train_start(&mut self, done: usize, total: usize) {
        self.steps = total;
        self.call("train", done, f64::NAN);
    }
    fn train_step(&mut self, s: &StepStats) {
        self.call("train", s.step + 1, s.total);
    }
    fn polish_step(&mut self, done: usize, total: usize, loss: f64) {
        self.steps = total;
        self.call("polish", done, loss);
    }
    fn should_stop(&mut self) -> bool {
        self.error.is_some()
    }
}

/// The accuracy target of a fit's options (`target_hausdorff`, `keep_topology`,
/// `max_sites`, taken out of `json`), or `None` when neither goal is asked for.
fn accuracy_goal(json: &mut serde_json::Map<String, serde_json::Value>) -> PyResult<Option<::fit::AccuracyGoal>> {
    let bad = |what: &str, v: &serde_json::Value| input_error(format!("fit options: {what} = {v} is not valid"));
    let hausdorff = match json.remove("target_hausdorff") {
        None | Some(serde_json::Value::Null) => None,
        Some(v) => Some(v.as_f64().ok_or_else(|| bad("target_hausdorff", &v))?),
    };
    let keep_topology = match json.remove("keep_topology") {
        None | Some(serde_json::Value::Null) => false,
        Some(v) => v.as_bool().ok_or_else(|| bad("keep_topology", &v))?,
    };
    let max_sites = match json.remove("max_sites") {
        None | Some(serde_json::Value::Null) => ::fit::DEFAULT_MAX_SITES,
        Some(v) => v.as_u64().ok_or_else(|| bad("max_sites", &v))? as usize,
    };
    Ok(::fit::AccuracyGoal::asked(hausdorff, keep_topology, max_sites))
}

type FitBytes<'py> =
    (Bound<'py, PyBytes>, Bound<'py, PyBytes>, Bound<'py, PyBytes>, Bound<'py, PyBytes>, Bound<'py, PyBytes>, String);

/// The main job (`fit::fit`, as `voronoi-fit MESH`): options as JSON (`fit::FitOptions`'
/// fields). Returns (sites in the unit cube, labels, 4×4 unit-cube → mesh transform, crust
/// vertices in the mesh frame at float64, crust faces, report JSON).
#[pyfunction]
#[pyo3(name = "fit", signature = (vertices, faces, name, options_json, callback=None, float32=false))]
fn fit_mesh<'py>(
    py: Python<'py>,
    vertices: &[u8],
    faces: &[u8],
    name: &str,
    options_json: &str,
    callback: Option<Py<PyAny>>,
    float32: bool,
) -> PyResult<FitBytes<'py>> {
    let input = mesh(vertices, faces, name)?;
    let mut json: serde_json::Map<String, serde_json::Value> =
        serde_json::from_str(options_json).map_err(|e| input_error(format!("fit options: {e}")))?;
    // The accuracy target's three options are the job's, not `FitOptions`' (as on the CLI:
    // `--target-hausdorff`, `--keep-topology`, `--max-sites`).
    let goal = accuracy_goal(&mut json)?;
    let options: FitOptions = serde_json::from_value(serde_json::Value::Object(json))
        .map_err(|e| input_error(format!("fit options: {e}")))?;
    let mut config = options.to_config(name).map_err(input_error)?;
    // float64 unless asked: the CLI rounds (and checks again) at float32 only for glTF, and
    // so does `float32` here, for a crust that will be saved as GLB.
    config.output_precision = if float32 { ::crust::output::Precision::F32 } else { ::crust::output::Precision::F64 };
    let mut progress = PyProgress { callback, error: None, steps: 0 };
    let result = py.allow_threads(|| match &goal {
        Some(goal) => ::fit::fit_to_accuracy(&input, &config, goal, &mut progress),
        None => ::fit::fit(&input, &config, &mut progress),
    });
    if let Some(e) = progress.error.take() {
        return Err(e);
    }
    let out = result.map_err(|e| match e {
        e if e.is_input_fault() => input_error(e),
        e => failure(e),
    })?;
    let mut report = out.report;
    report.total_seconds = report.total_seconds.max(0.0);
    let json = serde_json::to_string(&report).map_err(failure)?;
    let labels: Vec<u8> = out.sites.inside.iter().map(|&b| b as u8).collect();
    Ok((
        f64_bytes(py, &out.sites.sites),
        PyBytes::new(py, &labels),
        f64_bytes(py, &out.sites.transform),
        f64_bytes(py, &out.crust.positions),
        u32_bytes(py, &out.crust.triangles),
        json,
    ))
}

/// The checked crust of labelled sites in the unit cube (as a sites file holds them),
/// mapped by the 4×4 `transform` (16 float64, row-major; identity when empty) at float64:
/// (vertices, faces).
#[pyfunction]
#[pyo3(name = "crust")]
fn crust_of_sites<'py>(py: Python<'py>, sites: &[u8], labels: &[u8], transform: &[u8]) -> PyResult<MeshBytes<'py>> {
    let sites = rows_f64(sites, "sites")?;
    if labels.len() != sites.len() {
        return Err(input_error(format!("{} labels for {} sites: give one per site", labels.len(), sites.len())));
    }
    if let Some(i) = sites.iter().position(|p| !p.iter().all(|x| (0.0..=1.0).contains(x))) {
        return Err(input_error(format!(
            "site {i} {:?} is outside the unit cube; sites are stored in [0, 1]³ with a transform to the mesh frame",
            sites[i]
        )));
    }
    let inside: Vec<bool> = labels.iter().map(|&b| b != 0).collect();
    let mut m = [[0.0; 4]; 4];
    if transform.is_empty() {
        (0..4).for_each(|i| m[i][i] = 1.0);
    } else if transform.len() == 128 {
        for (k, c) in transform.chunks_exact(8).enumerate() {
            m[k / 4][k % 4] = f64::from_le_bytes(c.try_into().unwrap_or([0; 8]));
        }
    } else {
        return Err(input_error("transform: give a 4×4 float64 matrix"));
    }
    let result = py.allow_threads(|| -> Result<TriMesh, String> {
        let c =
            ::crust::Crust::extract(&sites, &inside, &::crust::CrustConfig::default()).map_err(|e| e.to_string())?;
        let f = ::crust::output::finalize(&c, m, ::crust::output::Precision::F64).map_err(|e| e.to_string())?;
        Ok(f.mesh)
    });
    let m = result.map_err(input_error)?;
    Ok((f64_bytes(py, &m.positions), u32_bytes(py, &m.triangles)))
}

/// Writes a mesh atomically (temporary file, then rename) in the format of the path's
/// extension (.glb, .gltf, .obj, .ply), as the CLI writes its outputs.
/// `normals`: `flat`, `smooth` or `crease[:DEG]` ([`mesh_io::Normals`]; glTF only).
#[pyfunction]
#[pyo3(signature = (path, vertices, faces, normals = "flat"))]
fn save_mesh(py: Python<'_>, path: &str, vertices: &[u8], faces: &[u8], normals: &str) -> PyResult<()> {
    let m = mesh(vertices, faces, path)?;
    let normals = mesh_io::Normals::parse(normals).map_err(input_error)?;
    py.allow_threads(|| mesh_io::write_mesh_with(std::path::Path::new(path), &m, normals)).map_err(|e| {
        if e.kind == mesh_io::ErrorKind::Write {
            failure(e)
        } else {
            input_error(e)
        }
    })
}

/// Writes a sites file (`.npz`: sites in the unit cube, labels, 4×4 transform) atomically,
/// the file `voronoi-fit crust` reads.
#[pyfunction]
fn save_sites(py: Python<'_>, path: &str, sites: &[u8], labels: &[u8], transform: &[u8]) -> PyResult<()> {
    let sites = rows_f64(sites, "sites")?;
    if labels.len() != sites.len() || transform.len() != 128 {
        return Err(input_error("save_sites: one label per site and a 4×4 float64 transform"));
    }
    let mut m = [[0.0; 4]; 4];
    for (k, c) in transform.chunks_exact(8).enumerate() {
        m[k / 4][k % 4] = f64::from_le_bytes(c.try_into().unwrap_or([0; 8]));
    }
    let file = ::crust::SitesFile { sites, inside: labels.iter().map(|&b| b != 0).collect(), transform: m };
    py.allow_threads(|| file.write(std::path::Path::new(path))).map_err(failure)
}

fn oracle(v: &[u8], f: &[u8]) -> PyResult<occupancy::MeshOracle> {
    let m = mesh(v, f, "mesh")?;
    occupancy::MeshOracle::from_mesh(&m, &occupancy::Config::default()).map_err(|e| input_error(format!("mesh: {e}")))
}

/// Generalized winding numbers of the query points (fast: Barill's expansion with the
/// exact fallback near ±0.5; or exact).
#[pyfunction]
fn winding_number<'py>(
    py: Python<'py>,
    v: &[u8],
    f: &[u8],
    queries: &[u8],
    exact: bool,
) -> PyResult<Bound<'py, PyBytes>> {
    let q = rows_f64(queries, "queries")?;
    let o = oracle(v, f)?;
    let mode = if exact { occupancy::WindingMode::Exact } else { occupancy::WindingMode::Fast };
    let w = py.allow_threads(|| o.winding_numbers(&q, mode)).map_err(input_error)?;
    Ok(scalar_bytes(py, &w))
}

/// Signed distance (negative inside by the workspace's one inside rule, |w| ≥ 0.5), the
/// closest points and their triangles.
#[pyfunction]
fn signed_distance<'py>(
    py: Python<'py>,
    v: &[u8],
    f: &[u8],
    queries: &[u8],
) -> PyResult<(Bound<'py, PyBytes>, Bound<'py, PyBytes>, Bound<'py, PyBytes>)> {
    let q = rows_f64(queries, "queries")?;
    let o = oracle(v, f)?;
    let config = occupancy::Config::default();
    let (w, c) = py
        .allow_threads(|| -> Result<_, occupancy::OccupancyError> {
            Ok((o.winding_numbers(&q, occupancy::WindingMode::Fast)?, o.closest_points(&q)?))
        })
        .map_err(input_error)?;
    let sdf: Vec<f64> = w
        .iter()
        .zip(&c)
        .map(|(&w, c)| if config.is_inside_winding(w) { -c.squared_distance.sqrt() } else { c.squared_distance.sqrt() })
        .collect();
    let points: Vec<[f64; 3]> = c.iter().map(|c| c.point).collect();
    let tris: Vec<[u32; 1]> = c.iter().map(|c| [c.triangle]).collect();
    Ok((scalar_bytes(py, &sdf), f64_bytes(py, &points), u32_bytes(py, &tris)))
}

/// Exact 3D Delaunay tetrahedralization: positively oriented finite tetrahedra as indices
/// into `points`.
#[pyfunction]
fn delaunay<'py>(py: Python<'py>, points: &[u8]) -> PyResult<Bound<'py, PyBytes>> {
    let p = rows_f64(points, "points")?;
    let tets = py
        .allow_threads(|| delaunay3::Delaunay3::new(&p).map(|d| d.finite_tets_input_indices()))
        .map_err(|e| input_error(format!("points: {e}")))?;
    Ok(u32_bytes(py, &tets))
}

/// Certified two-sided Hausdorff distance between two meshes: (lo, hi).
#[pyfunction]
fn hausdorff(py: Python<'_>, va: &[u8], fa: &[u8], vb: &[u8], fb: &[u8], rel_tolerance: f64) -> PyResult<(f64, f64)> {
    let (a, b) = (mesh(va, fa, "first mesh")?, mesh(vb, fb, "second mesh")?);
    let opts = metrics::CertifiedOptions { rel_tolerance, ..Default::default() };
    let h = py.allow_threads(|| metrics::hausdorff_certified(&a, &b, &opts)).map_err(input_error)?;
    Ok((h.lo, h.hi))
}

/// The `voronoi-fit eval` report of a prediction against a reference, as JSON.
#[pyfunction]
fn evaluate(py: Python<'_>, vr: &[u8], fr: &[u8], vp: &[u8], fp: &[u8]) -> PyResult<String> {
    let (r, p) = (mesh(vr, fr, "reference")?, mesh(vp, fp, "prediction")?);
    let report =
        py.allow_threads(|| metrics::evaluate(&r, &p, &metrics::EvalOptions::default())).map_err(input_error)?;
    serde_json::to_string(&report).map_err(failure)
}

/// The viewer page of a crust (`viewer::write_page`, as `voronoi-fit view`): paths of the
/// crust and, optionally, the input, report, sites file, cells and page; the fresh samples
/// checked for misclassified points. Returns (the page's path, notes on what it left out).
#[pyfunction]
#[pyo3(signature = (crust, input=None, report=None, sites=None, cells=None, out=None, check_samples=::viewer::DEFAULT_CHECK_SAMPLES))]
#[allow(clippy::too_many_arguments)]
fn view(
    py: Python<'_>,
    crust: &str,
    input: Option<&str>,
    report: Option<&str>,
    sites: Option<&str>,
    cells: Option<&str>,
    out: Option<&str>,
    check_samples: usize,
) -> PyResult<(String, Vec<String>)> {
    let path = |p: Option<&str>| p.map(std::path::PathBuf::from);
    let options = ::viewer::PageOptions {
        crust: crust.into(),
        input: path(input),
        report: path(report),
        sites: path(sites),
        cells: path(cells),
        output: path(out),
        check_samples,
    };
    let page = py.allow_threads(|| ::viewer::write_page(&options)).map_err(|e| {
        if e.is_input_fault() {
            input_error(e)
        } else {
            failure(e)
        }
    })?;
    Ok((page.path.display().to_string(), page.notes))
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("InputError", m.py().get_type::<InputError>())?;
    m.add("Error", m.py().get_type::<Error>())?;
    m.add_function(wrap_pyfunction!(load_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(fit_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(crust_of_sites, m)?)?;
    m.add_function(wrap_pyfunction!(winding_number, m)?)?;
    m.add_function(wrap_pyfunction!(signed_distance, m)?)?;
    m.add_function(wrap_pyfunction!(delaunay, m)?)?;
    m.add_function(wrap_pyfunction!(hausdorff, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate, m)?)?;
    m.add_function(wrap_pyfunction!(save_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(save_sites, m)?)?;
    m.add_function(wrap_pyfunction!(view, m)?)?;
    m.add_function(wrap_pyfunction!(batch::batch_plan, m)?)?;
    m.add_function(wrap_pyfunction!(batch::batch_finished, m)?)?;
    m.add_function(wrap_pyfunction!(batch::batch_fit_into, m)?)?;
    m.add_function(wrap_pyfunction!(batch::batch_publish, m)?)?;
    m.add_function(wrap_pyfunction!(batch::batch_write_summary, m)?)?;
    Ok(())
}
