//! The HTML page: locating the files, the summary, loss and timing tables, the
//! misclassified points, the embedded arrays and the template fill.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use base64::Engine as _;
use mesh_io::TriMesh;
use serde_json::Value;

use crate::{group, Error};

const TEMPLATE: &str = include_str!("../assets/viewer.html");
const APP: &str = include_str!("../assets/viewer.js");
const THREE_CORE: &str = include_str!("../assets/three.core.min.js");
const THREE_MODULE: &str = include_str!("../assets/three.module.min.js");
const ORBIT: &str = include_str!("../assets/OrbitControls.js");
const THREE_LICENSE: &str = include_str!("../assets/LICENSE");

/// Fresh samples drawn by default to find misclassified points.
pub const DEFAULT_CHECK_SAMPLES: usize = 200_000;

/// What goes into a page: the crust and, optionally, where its companions are.
#[derive(Clone, Debug)]
pub struct PageOptions {
    /// The crust (OUT.glb from the main job, or any mesh file).
    pub crust: PathBuf,
    /// The input mesh. `None`: the path OUT.report.json names.
    pub input: Option<PathBuf>,
    /// The fit's report. `None`: OUT.report.json beside the crust.
    pub report: Option<PathBuf>,
    /// The sites file. `None`: OUT.sites.npz beside the crust.
    pub sites: Option<PathBuf>,
    /// The convex cells. `None`: OUT.cells.glb beside the crust, if it exists.
    pub cells: Option<PathBuf>,
    /// The page. `None`: OUT.html beside the crust.
    pub output: Option<PathBuf>,
    /// Fresh samples (half uniform in the sites' cube, half within 1% of the diagonal of
    /// the surface) classified by the sites against the input to find misclassified
    /// points; 0 for none.
    pub check_samples: usize,
}

impl PageOptions {
    /// The page of `crust`, everything else found beside it.
    pub fn new(crust: impl Into<PathBuf>) -> Self {
        PageOptions {
            crust: crust.into(),
            input: None,
            report: None,
            sites: None,
            cells: None,
            output: None,
            check_samples: DEFAULT_CHECK_SAMPLES,
        }
    }
}

/// A page written by [`write_page`].
#[derive(Clone, Debug)]
pub struct Page {
    /// Where it is.
    pub path: PathBuf,
    /// Its size in bytes.
    pub bytes: usize,
    /// What was left out and why (e.g. `no report at OUT.report.json`).
    pub notes: Vec<String>,
}

/// The main job's `--html`: the page of a fit just written (OUT.html beside OUT.glb).
/// Returns the page's path.
pub fn write_fit_page(crust: &Path, input: &Path, report: &Path, sites: &Path) -> Result<PathBuf, Error> {
    let options = PageOptions {
        input: Some(input.to_path_buf()),
        report: Some(report.to_path_buf()),
        sites: Some(sites.to_path_buf()),
        ..PageOptions::new(crust)
    };
    Ok(write_page(&options)?.path)
}

/// `BASE.suffix` beside the crust `BASE.ext`.
fn beside(crust: &Path, suffix: &str) -> PathBuf {
    PathBuf::from(format!("{}{suffix}", crust.with_extension("").display()))
}

/// A file from a flag (must exist) or its default place (may be absent: `None`).
fn locate(
    flag: &Option<PathBuf>,
    default: PathBuf,
    what: &str,
    notes: &mut Vec<String>,
) -> Result<Option<PathBuf>, Error> {
    match flag {
        Some(p) if p.is_file() => Ok(Some(p.clone())),
        Some(p) => Err(Error::input(p, format!("no such file (the {what} given with its flag)"))),
        None if default.is_file() => Ok(Some(default)),
        None => {
            notes.push(format!("no {what} at {}", default.display()));
            Ok(None)
        }
    }
}

fn read_report(path: &Path) -> Result<Value, Error> {
    let text =
        std::fs::read_to_string(path).map_err(|e| Error::input(path, format!("cannot read the report ({e})")))?;
    let v: Value = serde_json::from_str(&text).map_err(|e| {
        Error::input(
            path,
            format!("not a voronoi-fit report: invalid JSON ({e}); give the OUT.report.json the main job wrote"),
        )
    })?;
    match v.get("format_version").and_then(Value::as_u64) {
        Some(1) => Ok(v),
        Some(n) => Err(Error::input(path, format!("report format_version {n} is not supported (this viewer reads 1)"))),
        None => Err(Error::input(
            path,
            "not a voronoi-fit report: no format_version; give the OUT.report.json the main job wrote",
        )),
    }
}

/// The input mesh path: the flag, or the report's `input.path` (as written, or relative to
/// the report's folder).
fn input_path(
    options: &PageOptions,
    report: Option<(&Path, &Value)>,
    notes: &mut Vec<String>,
) -> Result<Option<PathBuf>, Error> {
    if options.input.is_some() {
        return locate(&options.input, PathBuf::new(), "input mesh", notes);
    }
    let Some((rpath, report)) = report else {
        notes.push("no input mesh (give --input MESH, or a report that names it)".into());
        return Ok(None);
    };
    let Some(named) = report.pointer("/input/path").and_then(Value::as_str) else {
        return Err(Error::input(rpath, "the report has no input.path; give --input MESH"));
    };
    let named = PathBuf::from(named);
    let candidates = [named.clone(), rpath.parent().unwrap_or(Path::new(".")).join(&named)];
    match candidates.iter().find(|p| p.is_file()) {
        Some(p) => Ok(Some(p.clone())),
        None => {
            notes.push(format!(
                "the input {} named by {} is not there (give --input MESH)",
                named.display(),
                rpath.display()
            ));
            Ok(None)
        }
    }
}

/// Embedded arrays: `<script type="application/octet-stream">` blocks of base64.
#[derive(Default)]
struct Blobs {
    html: String,
    count: usize,
}

impl Blobs {
    fn add(&mut self, bytes: &[u8]) -> String {
        self.count += 1;
        let id = format!("vf-data-{}", self.count);
        let _ = write!(self.html, "<script type=\"application/octet-stream\" id=\"{id}\">");
        base64::engine::general_purpose::STANDARD.encode_string(bytes, &mut self.html);
        self.html.push_str("</script>\n");
        id
    }

    fn points(&mut self, pts: &[[f64; 3]], center: [f64; 3]) -> String {
        let b: Vec<u8> =
            pts.iter().flat_map(|p| (0..3).flat_map(move |k| ((p[k] - center[k]) as f32).to_le_bytes())).collect();
        self.add(&b)
    }

    fn mesh(&mut self, m: &TriMesh, center: [f64; 3]) -> Value {
        let positions = self.points(&m.positions, center);
        let idx: Vec<u8> = m.triangles.iter().flat_map(|t| t.iter().flat_map(|v| v.to_le_bytes())).collect();
        let indices = self.add(&idx);
        serde_json::json!({ "positions": positions, "indices": indices, "triangles": m.triangles.len() })
    }
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// Replace each `{{NAME}}` of `template` once, scanning only the template (inserted text is
/// never rescanned).
fn fill(template: &str, values: &[(&str, &str)]) -> Result<String, Error> {
    let mut out = String::with_capacity(template.len() + values.iter().map(|v| v.1.len()).sum::<usize>());
    let mut rest = template;
    while let Some(i) = rest.find("{{") {
        out.push_str(&rest[..i]);
        let j = rest[i..].find("}}").ok_or_else(|| Error::Page("viewer template: unclosed {{".into()))? + i;
        let name = &rest[i + 2..j];
        let v = values
            .iter()
            .find(|v| v.0 == name)
            .ok_or_else(|| Error::Page(format!("viewer template: no value for {name}")))?;
        out.push_str(v.1);
        rest = &rest[j + 2..];
    }
    out.push_str(rest);
    Ok(out)
}

/// Text that goes inside a `<script>` element must not end it early.
fn script_safe(name: &str, s: &str) -> Result<(), Error> {
    let lower = s.to_ascii_lowercase();
    if lower.contains("</script") || lower.contains("<!--") {
        return Err(Error::Page(format!("{name} cannot be inlined: it contains </script or <!--")));
    }
    Ok(())
}

fn fmt_num(v: Option<f64>, digits: usize) -> String {
    v.map_or_else(|| "n/a".into(), |x| format!("{x:.digits$}"))
}

fn summary_html(
    report: Option<&Value>,
    crust: &TriMesh,
    input: Option<&TriMesh>,
    wrong: Option<(usize, usize)>,
) -> String {
    let mut rows: Vec<(String, String)> = Vec::new();
    let f = |p: &str| report.and_then(|r| r.pointer(p)).and_then(Value::as_f64);
    if let Some(inp) = input {
        rows.push(("input triangles".into(), group(inp.triangles.len())));
    }
    rows.push(("crust triangles".into(), group(crust.triangles.len())));
    if let Some(r) = report {
        let diag = input.map(|m| m.diagonal());
        rows.push(("sites (trainable)".into(), fmt_num(f("/settings/train/num_sites"), 0)));
        rows.push(("sites in the file".into(), fmt_num(f("/crust/num_sites"), 0)));
        rows.push(("training steps".into(), fmt_num(f("/settings/train/steps"), 0)));
        rows.push((
            "misclassified".into(),
            format!("{} %", fmt_num(f("/quality/misclassification").map(|x| 100.0 * x), 3)),
        ));
        rows.push((
            "— uniform / near-surface".into(),
            format!(
                "{} / {} %",
                fmt_num(f("/quality/misclassification_uniform").map(|x| 100.0 * x), 3),
                fmt_num(f("/quality/misclassification_near_surface").map(|x| 100.0 * x), 3)
            ),
        ));
        let pct = |x: Option<f64>| match (x, diag) {
            (Some(x), Some(d)) if d > 0.0 => format!("{:.3} % of diagonal", 100.0 * x / d),
            (Some(x), _) => format!("{x:.4e}"),
            _ => "n/a".into(),
        };
        rows.push(("Hausdorff (certified, upper)".into(), pct(f("/metrics/hausdorff/hi"))));
        rows.push(("Chamfer L1".into(), pct(f("/metrics/surface/chamfer_l1"))));
        rows.push(("F-score".into(), fmt_num(f("/metrics/surface/fscore"), 4)));
        rows.push(("normal consistency".into(), fmt_num(f("/metrics/surface/normal_consistency"), 4)));
        rows.push(("IoU".into(), fmt_num(f("/metrics/iou/iou"), 4)));
        rows.push((
            "components / genus".into(),
            format!("{} / {}", fmt_num(f("/crust/num_components"), 0), fmt_num(f("/crust/genus"), 0)),
        ));
        rows.push(("total time".into(), format!("{} s", fmt_num(f("/total_seconds"), 1))));
        let _ = r;
    }
    if let Some((n, total)) = wrong {
        rows.push(("misclassified here".into(), format!("{} of {} fresh samples", group(n), group(total))));
    }
    let mut html = String::from("<table>");
    for (k, v) in rows {
        let _ = write!(html, "<tr><td>{}</td><td class=\"num\">{}</td></tr>", escape(&k), escape(&v));
    }
    html.push_str("</table>");
    html
}

fn losses_html(report: Option<&Value>) -> String {
    let none = "<p class=\"note\">No report: no losses to show.</p>".to_string();
    let Some(l) = report.and_then(|r| r.get("losses")) else { return none };
    let cols: Vec<&str> = l
        .get("columns")
        .and_then(Value::as_array)
        .map(|c| c.iter().filter_map(Value::as_str).collect())
        .unwrap_or_default();
    let rows: Vec<Vec<f64>> = l
        .get("rows")
        .and_then(Value::as_array)
        .map(|rs| {
            rs.iter()
                .filter_map(|r| r.as_array().map(|r| r.iter().map(|x| x.as_f64().unwrap_or(f64::NAN)).collect()))
                .collect()
        })
        .unwrap_or_default();
    let Some(step) = cols.iter().position(|c| *c == "step") else { return none };
    let series: Vec<plot::Series> = cols
        .iter()
        .enumerate()
        .filter(|(_, c)| !matches!(**c, "step" | "lr" | "beta" | "max_move"))
        .filter_map(|(k, c)| {
            let points: Vec<(f64, f64)> = rows.iter().filter_map(|r| Some((*r.get(step)? + 1.0, *r.get(k)?))).collect();
            points.iter().any(|p| p.1 > 0.0).then(|| plot::Series { name: c.replace('_', " "), points, band: None })
        })
        .collect();
    let chart = plot::Chart {
        title: String::new(),
        x_label: "step".into(),
        y_label: "loss".into(),
        log_x: false,
        log_y: true,
        series,
    };
    match chart.try_to_svg() {
        Ok(svg) => svg,
        Err(_) => none,
    }
}

fn timings_html(report: Option<&Value>) -> String {
    let Some(t) = report.and_then(|r| r.get("timings_seconds")).and_then(Value::as_object) else {
        return "<p class=\"note\">No report: no timings to show.</p>".into();
    };
    // Pipeline order first, then any stage this viewer does not know yet.
    let order = ["load", "oracle", "sample", "train", "crust", "evaluate", "metrics"];
    let rank = |k: &str| order.iter().position(|o| *o == k).unwrap_or(order.len());
    let mut stages: Vec<(&String, f64)> = t.iter().filter_map(|(k, v)| Some((k, v.as_f64()?))).collect();
    stages.sort_by_key(|s| rank(s.0));
    let max = stages.iter().map(|s| s.1).fold(0.0, f64::max).max(1e-9);
    let mut html = String::from("<table>");
    for (k, s) in &stages {
        let _ = write!(
            html,
            "<tr><td>{}</td><td class=\"num\">{s:.2} s</td><td style=\"width:50%\"><div class=\"bar\" style=\"width:{:.1}%\"></div></td></tr>",
            escape(k),
            100.0 * s / max
        );
    }
    let total: f64 = stages.iter().map(|s| s.1).sum();
    let _ =
        write!(html, "<tr><td><b>all stages</b></td><td class=\"num\"><b>{total:.2} s</b></td><td></td></tr></table>");
    html
}

/// The solid the fit stood for, from its report: `Some(h)` for a shell of half-thickness
/// `h` (input units) around the surface, `None` for the winding-number solid (also when
/// there is no report, or one written before shells existed).
fn shell_half_thickness(report: Option<&Value>) -> Option<f64> {
    let solid = report?.get("solid")?;
    (solid.get("rule")?.as_str()? == "shell").then(|| solid.get("half_thickness")?.as_f64()).flatten()
}

/// Fresh samples (mesh frame) misclassified by the sites, and how many were drawn. The
/// truth is the input's winding-number solid (the workspace's one inside rule), or the
/// shell of half-thickness `shell` around its surface when the fit used one.
fn misclassified(
    input: &TriMesh,
    sites: &crust::SitesFile,
    n: usize,
    shell: Option<f64>,
) -> Result<(Vec<[f64; 3]>, usize), Error> {
    use occupancy::sample::{near_surface, uniform_in_box, SurfaceSampler};
    let oracle = occupancy::MeshOracle::from_mesh(input, &occupancy::Config::default())?;
    let sampler = SurfaceSampler::from_mesh(input)?;
    let (a, b) = (sites.to_mesh_frame([0.0; 3]), sites.to_mesh_frame([1.0; 3]));
    let lo = [0, 1, 2].map(|k| a[k].min(b[k]));
    let hi = [0, 1, 2].map(|k| a[k].max(b[k]));
    let mut points = uniform_in_box(lo, hi, n / 2, 1)?;
    points.extend(near_surface(&sampler, n - n / 2, &[0.01 * input.diagonal()], 1)?);
    let truth = match shell {
        Some(h) => oracle.closest_points(&points)?.iter().map(|c| c.squared_distance <= h * h).collect(),
        None => oracle.inside(&points)?,
    };
    let mesh_sites: Vec<[f64; 3]> = sites.sites.iter().map(|&p| sites.to_mesh_frame(p)).collect();
    let predicted = soft_voronoi::classify(&mesh_sites, &sites.inside, &points);
    let wrong = points.iter().zip(truth.iter().zip(&predicted)).filter(|(_, (t, p))| t != p).map(|(p, _)| *p).collect();
    Ok((wrong, points.len()))
}

/// Writes the page (atomically) and returns where, its size and what it left out.
pub fn write_page(options: &PageOptions) -> Result<Page, Error> {
    let out = options.output.clone().unwrap_or_else(|| options.crust.with_extension("html"));
    if out.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() != Some("html") {
        return Err(Error::input(&out, "the page must be an .html file"));
    }
    mesh_io::check_output_location(&out)?;
    let mut notes = Vec::new();
    let crust = mesh_io::read_mesh(&options.crust)?;
    let report_path = locate(&options.report, beside(&options.crust, ".report.json"), "report", &mut notes)?;
    let report = report_path.as_deref().map(read_report).transpose()?;
    let input_path = input_path(options, report_path.as_deref().zip(report.as_ref()), &mut notes)?;
    let input = input_path.as_deref().map(mesh_io::read_mesh).transpose()?;
    let sites_path = locate(&options.sites, beside(&options.crust, ".sites.npz"), "sites file", &mut notes)?;
    let sites = sites_path.as_deref().map(crust::SitesFile::read).transpose()?;
    let cells_path = match &options.cells {
        Some(_) => locate(&options.cells, PathBuf::new(), "cells", &mut notes)?,
        None => Some(beside(&options.crust, ".cells.glb")).filter(|p| p.is_file()),
    };
    let cells = cells_path.as_deref().map(mesh_io::read_mesh).transpose()?;
    let wrong = match (&input, &sites) {
        (Some(i), Some(s)) if options.check_samples > 0 => {
            Some(misclassified(i, s, options.check_samples, shell_half_thickness(report.as_ref()))?)
        }
        _ => None,
    };

    // One frame for everything: centred on the bounding box of the meshes (float32 keeps
    // its precision near the origin).
    let meshes = [Some(&crust), input.as_ref(), cells.as_ref()];
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for m in meshes.iter().flatten() {
        let (a, b) = m.bounding_box();
        for k in 0..3 {
            lo[k] = lo[k].min(a[k]);
            hi[k] = hi[k].max(b[k]);
        }
    }
    if lo[0] > hi[0] || lo[0].is_nan() {
        return Err(Error::input(&options.crust, "the crust has no vertices; nothing to show"));
    }
    let center = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
    let extent = [0, 1, 2].map(|k| hi[k] - lo[k]);
    let radius = 0.5 * (extent[0].powi(2) + extent[1].powi(2) + extent[2].powi(2)).sqrt();

    let mut blobs = Blobs::default();
    let mut meta_meshes = serde_json::Map::new();
    meta_meshes.insert("crust".into(), blobs.mesh(&crust, center));
    if let Some(m) = &input {
        meta_meshes.insert("input".into(), blobs.mesh(m, center));
    }
    if let Some(m) = &cells {
        meta_meshes.insert("cells".into(), blobs.mesh(m, center));
    }
    let mut meta_points = serde_json::Map::new();
    if let Some(s) = &sites {
        let (inside, outside): (Vec<_>, Vec<_>) = s.sites.iter().zip(&s.inside).partition(|(_, &i)| i);
        let to_mesh = |v: Vec<(&[f64; 3], &bool)>| v.into_iter().map(|(p, _)| s.to_mesh_frame(*p)).collect::<Vec<_>>();
        meta_points.insert("inside".into(), blobs.points(&to_mesh(inside), center).into());
        meta_points.insert("outside".into(), blobs.points(&to_mesh(outside), center).into());
    }
    if let Some((w, n)) = &wrong {
        meta_points.insert("wrong".into(), blobs.points(w, center).into());
        meta_points.insert("wrong_count".into(), w.len().into());
        meta_points.insert("samples".into(), (*n).into());
    }
    let name = |p: &Path| p.file_name().map_or_else(|| p.display().to_string(), |n| n.to_string_lossy().to_string());
    let title = match &input_path {
        Some(i) => format!("{} → {}", name(i), name(&options.crust)),
        None => name(&options.crust),
    };
    let subtitle = {
        let mut s = format!("crust {}", options.crust.display());
        for (what, p) in
            [("input", &input_path), ("report", &report_path), ("sites", &sites_path), ("cells", &cells_path)]
        {
            if let Some(p) = p {
                let _ = write!(s, " · {what} {}", p.display());
            }
        }
        s
    };
    let meta = serde_json::json!({
        "format_version": 1,
        "title": title,
        "radius": radius,
        "extent": extent,
        "center": center,
        "meshes": meta_meshes,
        "points": meta_points,
        "notes": notes,
    });
    let meta_text = serde_json::to_string(&meta)
        .map_err(|e| Error::Page(format!("viewer metadata: {e}")))?
        .replace("</", "<\\/")
        .replace("<!--", "<\\!--");
    for (n, s) in [
        ("three.core.min.js", THREE_CORE),
        ("three.module.min.js", THREE_MODULE),
        ("OrbitControls.js", ORBIT),
        ("viewer.js", APP),
    ] {
        script_safe(n, s)?;
    }
    let summary = summary_html(report.as_ref(), &crust, input.as_ref(), wrong.as_ref().map(|(w, n)| (w.len(), *n)));
    let page = fill(
        TEMPLATE,
        &[
            ("TITLE", &escape(&title)),
            ("SUBTITLE", &escape(&subtitle)),
            ("SUMMARY", &summary),
            ("LOSSES", &losses_html(report.as_ref())),
            ("TIMINGS", &timings_html(report.as_ref())),
            ("META", &meta_text),
            ("DATA", &blobs.html),
            ("THREE_CORE", THREE_CORE),
            ("THREE_MODULE", THREE_MODULE),
            ("ORBIT", ORBIT),
            ("THREE_LICENSE", THREE_LICENSE),
            ("APP", APP),
        ],
    )?;
    mesh_io::atomic_write(&out, |w| w.write_all(page.as_bytes()))?;
    Ok(Page { path: out, bytes: page.len(), notes })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vendored_scripts_can_be_inlined() {
        for s in [THREE_CORE, THREE_MODULE, ORBIT, APP] {
            assert!(script_safe("x", s).is_ok());
        }
        assert!(THREE_MODULE.contains("\"./three.core.min.js\""));
        assert!(ORBIT.contains("from 'three'"));
        // The licence goes into an HTML comment.
        assert!(!THREE_LICENSE.contains("--"));
    }

    #[test]
    fn fill_does_not_rescan_inserted_text() {
        let t = fill("a{{X}}b{{Y}}", &[("X", "{{Y}}"), ("Y", "1")]).ok();
        assert_eq!(t.as_deref(), Some("a{{Y}}b1"));
        assert!(fill("{{Z}}", &[]).is_err());
    }

    #[test]
    fn shell_from_report() {
        let r = |v: serde_json::Value| shell_half_thickness(Some(&v));
        assert_eq!(r(serde_json::json!({"solid": {"rule": "shell", "half_thickness": 0.5}})), Some(0.5));
        assert_eq!(r(serde_json::json!({"solid": {"rule": "winding", "half_thickness": null}})), None);
        assert_eq!(r(serde_json::json!({"format_version": 1})), None);
        assert_eq!(shell_half_thickness(None), None);
    }

    /// A tetrahedron as the crust, nothing beside it: a page with notes; a missing file
    /// given explicitly, or a non-.html page, is the input's fault and writes nothing.
    #[test]
    fn page_of_a_lone_crust_and_input_errors() {
        let dir = tempfile::tempdir().unwrap();
        let crust = dir.path().join("t.obj");
        std::fs::write(&crust, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n").unwrap();
        let page = write_page(&PageOptions::new(&crust)).unwrap();
        assert_eq!(page.path, dir.path().join("t.html"));
        let html = std::fs::read_to_string(&page.path).unwrap();
        assert_eq!(html.len(), page.bytes);
        assert!(html.contains("vf-data-1") && !html.contains("{{"));
        assert_eq!(page.notes.len(), 3, "{:?}", page.notes);

        let missing = PageOptions { report: Some(dir.path().join("nope.json")), ..PageOptions::new(&crust) };
        let e = write_page(&missing).unwrap_err();
        assert!(e.is_input_fault() && e.to_string().contains("nope.json"), "{e}");
        let bad_out = PageOptions { output: Some(dir.path().join("p.txt")), ..PageOptions::new(&crust) };
        assert!(write_page(&bad_out).unwrap_err().is_input_fault());
        assert!(!dir.path().join("p.txt").exists());
    }
}
