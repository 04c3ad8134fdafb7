//! The main job's picture, OUT.png: the input (top row) and the crust (bottom row) from
//! three sides.

use std::path::{Path, PathBuf};

use mesh_io::TriMesh;

use crate::{group, Error};

/// The figures of a fit named in the picture's title (from its report).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PictureFigures {
    /// Trainable sites (the report's `settings.train.num_sites`).
    pub sites_trained: usize,
    /// Sites in the sites file (`crust.num_sites`).
    pub sites_in_file: usize,
    /// Share of misclassified fresh samples (`quality.misclassification`).
    pub misclassification: f64,
    /// Triangles of the crust (`crust.num_triangles`).
    pub crust_triangles: usize,
}

/// `OUT.png` for the crust `OUT.glb`.
pub fn picture_path(crust: &Path) -> PathBuf {
    PathBuf::from(format!("{}.png", crust.with_extension("").display()))
}

/// The main job's picture: the input (top row) and the crust (bottom row) from three
/// sides, written atomically to `path`.
pub fn write_picture(
    path: &Path,
    input: &TriMesh,
    crust: &TriMesh,
    input_path: &Path,
    figures: &PictureFigures,
) -> Result<(), Error> {
    use plot::raster3d::{render, Model, Options, CRUST_COLOR, INPUT_COLOR};
    let name =
        input_path.file_name().map_or_else(|| input_path.display().to_string(), |n| n.to_string_lossy().to_string());
    let title = format!(
        "{name}: {} sites fitted ({} in the file), {:.2}% misclassified, crust of {} triangles",
        group(figures.sites_trained),
        group(figures.sites_in_file),
        100.0 * figures.misclassification,
        group(figures.crust_triangles)
    );
    let models = [
        Model { label: format!("input, {} triangles", group(input.triangles.len())), mesh: input, color: INPUT_COLOR },
        Model { label: format!("crust, {} triangles", group(crust.triangles.len())), mesh: crust, color: CRUST_COLOR },
    ];
    let image = render(&models, &Options { title, ..Default::default() })?;
    image.write_png(path).map_err(|source| Error::Picture { path: path.to_path_buf(), source: Box::new(source) })
}
