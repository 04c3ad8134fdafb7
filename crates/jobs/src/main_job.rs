//! The main job for one mesh, from a [`FitJob`] to the files on disk: OUT.glb (the crust),
//! OUT.sites.npz, OUT.png (the picture), OUT.report.json (written last: its presence
//! means the run finished), optionally OUT.html (the viewer page) and OUT.points.npz (the
//! fitted solid's occupancy samples, [`crate::occupancy_samples`]), and, while training,
//! OUT.ckpt.npz (every `checkpoint_every` steps and when stopped; removed when the run
//! finishes unless `keep_checkpoint`).

use std::path::PathBuf;
use std::time::Instant;

use fit::{Checkpointing, FitConfig, FitError, FitOptions, Progress, Stage};
use mesh_io::{Normals, OutputFormat};
use serde::{Deserialize, Serialize};
use soft_voronoi::StepStats;

use crate::occupancy_samples::{self, Normalisation};
use crate::{Error, OccupancySpec};

/// The main job's options: what to fit, how (the fit options) and what to write.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FitJob {
    /// Input mesh (.obj, .stl, .ply, .off, .glb, .gltf).
    pub mesh: PathBuf,
    /// Output crust (.glb, .gltf, .obj or .ply). `None`: MESH's stem + `.voronoi.glb` in
    /// the current directory. The sites file, report, picture and checkpoint go beside it.
    pub output: Option<PathBuf>,
    /// Normals in a glTF output (`flat`, `smooth`, `crease[:DEG]`).
    #[serde(with = "normals_text")]
    pub normals: Normals,
    /// The fit's settings (the CLI's flags; `fit::FitOptions`).
    pub options: FitOptions,
    /// Merge vertices closer than this share of the bounding-box diagonal before fitting.
    pub weld_tolerance: Option<f64>,
    /// Ask for a certified Hausdorff distance (share of the diagonal) instead of a K.
    pub target_hausdorff: Option<f64>,
    /// Budget of sites for `target_hausdorff`.
    pub max_sites: usize,
    /// Grow K (as `target_hausdorff` does) until the crust has the input's genus and
    /// components, where the report compares them.
    pub keep_topology: bool,
    /// Write a checkpoint every this many steps (0: only when stopped).
    pub checkpoint_every: usize,
    /// Continue from this checkpoint (its settings are used; the mesh must be the same).
    pub resume: Option<PathBuf>,
    /// Stop (with a checkpoint, as on an interrupt) after this many steps of this run.
    pub stop_after: Option<usize>,
    /// Keep OUT.ckpt.npz after a finished run.
    pub keep_checkpoint: bool,
    /// Also write OUT.html, the viewer page.
    pub html: bool,
    /// Also write OUT.points.npz: occupancy samples of the fitted solid in Occupancy
    /// Networks' layout ([`crate::occupancy_samples`]), seeded by the fit's seed.
    pub occupancy: Option<OccupancySpec>,
}

impl Default for FitJob {
    fn default() -> Self {
        FitJob {
            mesh: PathBuf::new(),
            output: None,
            normals: Normals::Flat,
            options: FitOptions::default(),
            weld_tolerance: None,
            target_hausdorff: None,
            max_sites: fit::DEFAULT_MAX_SITES,
            keep_topology: false,
            checkpoint_every: 100,
            resume: None,
            stop_after: None,
            keep_checkpoint: false,
            html: false,
            occupancy: None,
        }
    }
}

/// `Normals` as its text (`flat`, `smooth`, `crease:40`).
mod normals_text {
    use mesh_io::Normals;
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(n: &Normals, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&n.to_string())
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Normals, D::Error> {
        let text = String::deserialize(d)?;
        Normals::parse(&text).map_err(serde::de::Error::custom)
    }
}

/// Paths of the main job's outputs.
#[derive(Clone, Debug, PartialEq)]
pub struct Outputs {
    /// The crust.
    pub mesh: PathBuf,
    /// The sites file.
    pub sites: PathBuf,
    /// The report.
    pub report: PathBuf,
    /// The checkpoint.
    pub checkpoint: PathBuf,
    /// The occupancy samples (written only when asked for).
    pub points: PathBuf,
}

impl Outputs {
    /// The output paths of `job`, checked before any work: a known mesh format (else the
    /// input's fault), a writable folder (else not).
    pub fn of(job: &FitJob) -> Result<Outputs, Error> {
        let mesh = match &job.output {
            Some(p) => p.clone(),
            None => {
                let stem =
                    job.mesh.file_stem().map(|s| s.to_string_lossy().to_string()).unwrap_or_else(|| "mesh".into());
                PathBuf::from(format!("{stem}.voronoi.glb"))
            }
        };
        OutputFormat::from_path(&mesh)?;
        mesh_io::check_output_location(&mesh)?;
        let base = mesh.with_extension("");
        let with = |suffix: &str| PathBuf::from(format!("{}{suffix}", base.display()));
        Ok(Outputs {
            sites: with(".sites.npz"),
            report: with(".report.json"),
            checkpoint: with(".ckpt.npz"),
            points: with(".points.npz"),
            mesh,
        })
    }
}

/// What [`fit_to_files`] wrote.
pub struct Written {
    /// The output paths.
    pub outputs: Outputs,
    /// The report as written.
    pub report: fit::FitReport,
    /// The report's JSON text (as in OUT.report.json).
    pub json: String,
    /// The picture, OUT.png.
    pub picture: PathBuf,
    /// The viewer page, when asked for.
    pub page: Option<PathBuf>,
}

/// The validated fit settings of a job (through [`fit::FitOptions`], as the Python package
/// does), with its checkpointing, output precision and resumption.
fn config(job: &FitJob, out: &Outputs) -> Result<FitConfig, Error> {
    let mut c = job.options.to_config(&job.mesh.display().to_string())?;
    c.checkpointing = Some(Checkpointing { path: out.checkpoint.clone(), every: job.checkpoint_every });
    c.output_precision = crust::output::Precision::of_path(&out.mesh)?;
    if let Some(p) = &job.resume {
        return Ok(c.resume(p)?);
    }
    Ok(c)
}

fn read_input(job: &FitJob) -> Result<mesh_io::TriMesh, Error> {
    let mesh = mesh_io::read_mesh(&job.mesh)?;
    Ok(match job.weld_tolerance {
        Some(t) => mesh_io::weld::weld_tolerance(&mesh, t).0,
        None => mesh,
    })
}

/// Forwards to the caller's progress and stops after `stop_after` training steps.
struct StopAfter<'a> {
    inner: &'a mut dyn Progress,
    stop_after: Option<usize>,
    done_here: usize,
}

impl Progress for StopAfter<'_> {
    fn stage(&mut self, stage: Stage) {
        self.inner.stage(stage);
    }
    fn train_start(&mut self, done: usize, total: usize) {
        self.inner.train_start(done, total);
    }
    fn train_step(&mut self, stats: &StepStats) {
        self.done_here += 1;
        self.inner.train_step(stats);
    }
    fn should_stop(&mut self) -> bool {
        self.inner.should_stop() || self.stop_after.is_some_and(|n| self.done_here >= n)
    }
    fn train_end(&mut self) {
        self.inner.train_end();
    }
    fn polish_step(&mut self, done: usize, total: usize, loss: f64) {
        self.inner.polish_step(done, total, loss);
    }
}

/// The main job for one mesh, from options to the files on disk (crust, sites, picture,
/// report, optional page), printing nothing: `voronoi-fit MESH` and each mesh of a batch.
/// Training stops with a checkpoint ([`Error::Interrupted`]) when `progress` asks to
/// (`should_stop`, e.g. on Ctrl-C) or after `job.stop_after` steps.
pub fn fit_to_files(job: &FitJob, progress: &mut dyn Progress) -> Result<Written, Error> {
    let t_all = Instant::now();
    let out = Outputs::of(job)?;
    if let Some(spec) = &job.occupancy {
        spec.validate()?;
    }
    let config = config(job, &out)?;
    let input = read_input(job)?;
    if OutputFormat::from_path(&out.mesh)?.stores_f32() {
        // The crust is written in the input's frame; refuse now if float32 cannot resolve it.
        mesh_io::check_f32_resolution(&input, &job.mesh)?;
    }
    let mut progress = StopAfter { inner: progress, stop_after: job.stop_after, done_here: 0 };
    let result = match fit::AccuracyGoal::asked(job.target_hausdorff, job.keep_topology, job.max_sites) {
        Some(goal) => fit::fit_to_accuracy(&input, &config, &goal, &mut progress),
        None => fit::fit(&input, &config, &mut progress),
    };
    let result = match result {
        Err(FitError::Interrupted { step, steps, checkpoint }) => {
            return Err(Error::Interrupted { step, steps, checkpoint, mesh: job.mesh.clone(), output: out.mesh })
        }
        r => r?,
    };
    write_outputs(out, result, job, t_all)
}

/// Sites file, crust, occupancy samples (when asked for), picture and report, each
/// atomically (the report last: its presence means the run finished), and the optional
/// page.
fn write_outputs(out: Outputs, result: fit::FitOutput, job: &FitJob, t_all: Instant) -> Result<Written, Error> {
    result.sites.write(&out.sites)?;
    mesh_io::write_mesh_with(&out.mesh, &result.crust, job.normals)?;
    // The input is read again, as only the result reaches this function; reading is cheap
    // next to the fit.
    let input = read_input(job)?;
    let points = match &job.occupancy {
        Some(spec) => {
            write_occupancy(&out.points, spec, &input, &result, job)?;
            Some(out.points.display().to_string())
        }
        None => None,
    };
    // OUT.png: input and crust side by side from three views.
    let picture = viewer::picture_path(&out.mesh);
    let figures = viewer::PictureFigures {
        sites_trained: result.report.settings.train.num_sites,
        sites_in_file: result.report.crust.num_sites,
        misclassification: result.report.quality.misclassification,
        crust_triangles: result.report.crust.num_triangles,
    };
    viewer::write_picture(&picture, &input, &result.crust, &job.mesh, &figures)?;
    let mut report = result.report;
    report.outputs = fit::report::OutputsReport {
        crust: out.mesh.display().to_string(),
        sites: out.sites.display().to_string(),
        report: out.report.display().to_string(),
        crust_normals: job.normals.to_string(),
        occupancy: points,
    };
    report.total_seconds = t_all.elapsed().as_secs_f64();
    let json = serde_json::to_string_pretty(&report).map_err(|e| Error::Failure(format!("the report: {e}")))?;
    mesh_io::atomic_write(&out.report, |w| w.write_all(json.as_bytes()))?;
    if !job.keep_checkpoint && out.checkpoint.exists() {
        let _ = std::fs::remove_file(&out.checkpoint);
    }
    // The viewer page, from the files just written.
    let page =
        if job.html { Some(viewer::write_fit_page(&out.mesh, &job.mesh, &out.report, &out.sites)?) } else { None };
    Ok(Written { outputs: out, report, json, picture, page })
}

/// OUT.points.npz: `spec`'s samples of the fitted solid, in the frame of the input's
/// bounding box, labelled by the fitted sites (mapped to the input's frame, as the crust).
fn write_occupancy(
    path: &std::path::Path,
    spec: &OccupancySpec,
    input: &mesh_io::TriMesh,
    result: &fit::FitOutput,
    job: &FitJob,
) -> Result<(), Error> {
    let norm = Normalisation::of_mesh(input)
        .ok_or_else(|| Error::input_in(&job.mesh, "no bounding box to normalise the occupancy samples by"))?;
    let sites: Vec<[f64; 3]> = result.sites.sites.iter().map(|&p| result.sites.to_mesh_frame(p)).collect();
    let samples = occupancy_samples::occupancy_samples(
        spec,
        norm,
        &result.crust,
        &sites,
        &result.sites.inside,
        job.options.seed,
    )?;
    occupancy_samples::write_occupancy_samples(path, &samples)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_round_trip_through_json() {
        let job = FitJob {
            mesh: "a.obj".into(),
            normals: Normals::parse("crease:30").unwrap(),
            options: FitOptions { sites: Some(512), seed: 3, ..Default::default() },
            html: true,
            ..Default::default()
        };
        let text = serde_json::to_string(&job).unwrap();
        assert!(text.contains("\"crease:30\""), "{text}");
        assert_eq!(serde_json::from_str::<FitJob>(&text).unwrap(), job);
        assert!(serde_json::from_str::<FitJob>("{\"mesh\": \"a.obj\", \"nope\": 1}").is_err());
    }

    #[test]
    fn outputs_beside_the_crust_and_checked_first() {
        let dir = tempfile::tempdir().unwrap();
        let job = FitJob { mesh: "m.obj".into(), output: Some(dir.path().join("x.glb")), ..Default::default() };
        let o = Outputs::of(&job).unwrap();
        assert_eq!(o.sites, dir.path().join("x.sites.npz"));
        assert_eq!(o.report, dir.path().join("x.report.json"));
        assert_eq!(o.checkpoint, dir.path().join("x.ckpt.npz"));
        let bad = FitJob { output: Some(dir.path().join("x.xyz")), ..job };
        assert!(Outputs::of(&bad).unwrap_err().is_input_fault());
        let missing = FitJob { mesh: dir.path().join("none.obj"), output: Some(dir.path().join("y.glb")), ..bad };
        let e = fit_to_files(&missing, &mut fit::NoProgress).err().unwrap();
        assert!(e.is_input_fault() && e.to_string().contains("none.obj"), "{e}");
        assert!(!dir.path().join("y.glb").exists());
    }
}
