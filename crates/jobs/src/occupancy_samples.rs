//! Occupancy samples of the fitted solid, as training data in Occupancy Networks' layout
//! (`OUT.points.npz`): the points a network learns occupancy from, labelled by the solid
//! that was fitted (the nearest site's label, which is the inside of the watertight crust
//! written beside it), so a folder of meshes becomes training data without a separate
//! watertight-conversion and sampling pipeline.
//!
//! The layout is the one OccNet's `PointsField` reads (and its `sample_mesh.py` writes):
//!
//! - `points`: N×3 float16 in the normalised frame, the mesh's bounding box centred at the
//!   origin with its longest side 1; input coordinates are `points * scale + loc`.
//! - `occupancies`: `numpy.packbits` of the N labels (⌈N/8⌉ uint8, first point in the
//!   highest bit); `numpy.unpackbits(occupancies)[:N]` gives them back.
//! - `loc` (3,) float32 and `scale` () float32: the normalisation.
//!
//! The first `round(N × uniform_fraction)` points are uniform in the cube of side
//! `1 + padding` around the origin; the rest are the crust's surface points (area-weighted)
//! plus Gaussian offsets of standard deviation `sigma` (normalised units). Points are
//! labelled as stored (after rounding to float16), so every label is that of its stored
//! point. The samples depend only on the spec and the seed, not on the threads.

use std::path::Path;

use mesh_io::TriMesh;
use ndarray::{arr0, Array1, Array2};
use ndarray_npy::{WritableElement, WriteDataError};
use occupancy::sample::{near_surface, uniform_in_box, SurfaceSampler};
use serde::{Deserialize, Serialize};
use vf_common::npz::{NpzError, NpzOut};

use crate::Error;

/// What to sample: `points` in all, `uniform_fraction` of them uniform in the padded cube,
/// the rest near the crust's surface.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OccupancySpec {
    /// Points in all (≥ 1; OccNet's `points_size`).
    pub points: usize,
    /// Share of the points uniform in the padded cube, in [0, 1] (OccNet's
    /// `points_uniform_ratio`).
    pub uniform_fraction: f64,
    /// Standard deviation of the near-surface offsets, normalised units: the bounding box's
    /// longest side is 1 (≥ 0; OccNet's `points_sigma`).
    pub sigma: f64,
    /// The uniform cube's side is `1 + padding`, normalised units (≥ 0; OccNet's
    /// `points_padding`).
    pub padding: f64,
}

impl Default for OccupancySpec {
    fn default() -> Self {
        OccupancySpec { points: 100_000, uniform_fraction: 0.5, sigma: 0.01, padding: 0.1 }
    }
}

impl OccupancySpec {
    /// Checks the ranges above; the message names the CLI's flag.
    ///
    /// # Errors
    /// [`Error::Input`] naming the first value out of range.
    pub fn validate(&self) -> Result<(), Error> {
        let bad = |m: String| Err(Error::Input(m));
        if self.points == 0 {
            return bad("--occupancy must be at least 1 point".into());
        }
        if !(0.0..=1.0).contains(&self.uniform_fraction) {
            return bad(format!("--occupancy-uniform-fraction {} is outside [0, 1]", self.uniform_fraction));
        }
        if !(self.sigma.is_finite() && self.sigma >= 0.0) {
            return bad(format!("--occupancy-sigma {} must be finite and >= 0", self.sigma));
        }
        if !(self.padding.is_finite() && self.padding >= 0.0) {
            return bad(format!("--occupancy-padding {} must be finite and >= 0", self.padding));
        }
        Ok(())
    }
}

/// The normalisation of OccNet's layout: input coordinates = normalised × `scale` + `loc`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Normalisation {
    /// Centre of the bounding box, input units (as stored: float32).
    pub loc: [f32; 3],
    /// Its longest side, input units (as stored: float32).
    pub scale: f32,
}

impl Normalisation {
    /// The normalisation of `mesh`'s bounding box (of the vertices its triangles use).
    /// `None` when the box is empty, flat in every direction or not finite in float32.
    pub fn of_mesh(mesh: &TriMesh) -> Option<Self> {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for &v in mesh.triangles.iter().flatten() {
            let p = mesh.positions[v as usize];
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let extent = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
        let loc = [0, 1, 2].map(|k| (0.5 * lo[k] + 0.5 * hi[k]) as f32);
        let scale = extent as f32;
        (scale.is_finite() && scale > 0.0 && loc.iter().all(|c| c.is_finite())).then_some(Normalisation { loc, scale })
    }

    /// Normalised → input frame, in f64 from the stored float32 values.
    pub fn to_input(&self, u: [f64; 3]) -> [f64; 3] {
        [0, 1, 2].map(|k| u[k] * f64::from(self.scale) + f64::from(self.loc[k]))
    }

    /// Input → normalised frame.
    pub fn to_normalised(&self, p: [f64; 3]) -> [f64; 3] {
        [0, 1, 2].map(|k| (p[k] - f64::from(self.loc[k])) / f64::from(self.scale))
    }
}

/// Labelled points in OccNet's layout, as written.
#[derive(Clone, Debug, PartialEq)]
pub struct OccupancySamples {
    /// #N×3 points, normalised frame, as stored (float16).
    pub points: Vec<[half::f16; 3]>,
    /// #N labels (true = inside the fitted solid).
    pub inside: Vec<bool>,
    /// How the normalised frame maps to the input's.
    pub normalisation: Normalisation,
    /// Points drawn uniformly (the first ones).
    pub num_uniform: usize,
}

/// Draws and labels the samples of `spec`: `crust` (input frame) gives the surface to
/// sample near; `sites` (input frame) and their `inside` labels give each point's label
/// (its nearest site's); `normalisation` the frame; `seed` the samplers.
///
/// # Errors
/// [`Error::Input`] for a spec out of range or a crust without area (when near-surface
/// points are asked for).
pub fn occupancy_samples(
    spec: &OccupancySpec,
    normalisation: Normalisation,
    crust: &TriMesh,
    sites: &[[f64; 3]],
    inside: &[bool],
    seed: u64,
) -> Result<OccupancySamples, Error> {
    spec.validate()?;
    let sampling = |e: occupancy::OccupancyError| Error::Input(format!("occupancy samples: {e}"));
    let n = spec.points;
    let num_uniform = ((n as f64) * spec.uniform_fraction).round() as usize;
    let half_side = 0.5 * (1.0 + spec.padding);
    let mut points = uniform_in_box([-half_side; 3], [half_side; 3], num_uniform, seed).map_err(sampling)?;
    if n > num_uniform {
        let unit = TriMesh {
            positions: crust.positions.iter().map(|&p| normalisation.to_normalised(p)).collect(),
            triangles: crust.triangles.clone(),
        };
        let sampler = SurfaceSampler::from_mesh(&unit).map_err(sampling)?;
        points.extend(near_surface(&sampler, n - num_uniform, &[spec.sigma], seed).map_err(sampling)?);
    }
    let stored: Vec<[half::f16; 3]> = points.iter().map(|p| p.map(half::f16::from_f64)).collect();
    let queries: Vec<[f64; 3]> = stored.iter().map(|p| normalisation.to_input(p.map(f64::from))).collect();
    let labels = soft_voronoi::classify(sites, inside, &queries);
    Ok(OccupancySamples { points: stored, inside: labels, normalisation, num_uniform })
}

/// `numpy.packbits` of `bits`: eight to a byte, the first in the highest bit, the last
/// byte padded with zeros.
pub fn packbits(bits: &[bool]) -> Vec<u8> {
    bits.chunks(8).map(|c| c.iter().enumerate().fold(0u8, |b, (i, &x)| b | (u8::from(x) << (7 - i)))).collect()
}

/// A float16 array element for the `.npy` writer (`<f2`).
#[derive(Clone, Copy, Debug)]
struct F16(half::f16);

impl WritableElement for F16 {
    fn type_descriptor() -> py_literal::Value {
        py_literal::Value::String("<f2".into())
    }

    fn write<W: std::io::Write>(&self, mut writer: W) -> Result<(), WriteDataError> {
        writer.write_all(&self.0.to_le_bytes())?;
        Ok(())
    }

    fn write_slice<W: std::io::Write>(slice: &[Self], mut writer: W) -> Result<(), WriteDataError> {
        let bytes: Vec<u8> = slice.iter().flat_map(|x| x.0.to_le_bytes()).collect();
        writer.write_all(&bytes)?;
        Ok(())
    }
}

/// Writes `samples` to `path` (an `.npz`) atomically in OccNet's layout (the module's
/// documentation).
///
/// # Errors
/// [`Error::Mesh`] when the file cannot be written, [`Error::Failure`] when an array cannot
/// be encoded; both name the file.
pub fn write_occupancy_samples(path: &Path, samples: &OccupancySamples) -> Result<(), Error> {
    let encode = |e: NpzError| match e {
        NpzError::Write(e) => Error::from(e),
        NpzError::Encode(m) => Error::Failure(format!("{}: {m}", path.display())),
    };
    let n = samples.points.len();
    let points = Array2::from_shape_vec((n, 3), samples.points.iter().flatten().map(|&x| F16(x)).collect())
        .expect("N rows of 3 make an N×3 array");
    let mut npz = NpzOut::new();
    npz.add("points", &points).map_err(encode)?;
    npz.add("occupancies", &Array1::from(packbits(&samples.inside))).map_err(encode)?;
    npz.add("loc", &Array1::from(samples.normalisation.loc.to_vec())).map_err(encode)?;
    npz.add("scale", &arr0(samples.normalisation.scale)).map_err(encode)?;
    npz.write(path).map_err(encode)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packbits_as_numpy() {
        let bits = [true, false, false, false, false, false, false, true, true, true];
        assert_eq!(packbits(&bits), vec![0b1000_0001, 0b1100_0000]);
        assert!(packbits(&[]).is_empty());
    }

    #[test]
    fn specs_out_of_range_name_the_flag() {
        assert!(OccupancySpec::default().validate().is_ok());
        for (spec, flag) in [
            (OccupancySpec { points: 0, ..Default::default() }, "--occupancy "),
            (OccupancySpec { uniform_fraction: 1.5, ..Default::default() }, "--occupancy-uniform-fraction"),
            (OccupancySpec { sigma: f64::NAN, ..Default::default() }, "--occupancy-sigma"),
            (OccupancySpec { padding: -1.0, ..Default::default() }, "--occupancy-padding"),
        ] {
            let e = spec.validate().unwrap_err();
            assert!(e.is_input_fault() && e.to_string().contains(flag), "{e}");
        }
    }

    /// A cube of side 2 at (1, 1, 1) with one inside site at its centre among outside ones:
    /// labels follow the nearest site, the frame is OccNet's, and the file reads back.
    #[test]
    fn samples_of_a_cube_are_labelled_by_the_nearest_site_and_written() {
        let positions: Vec<[f64; 3]> =
            (0..8).map(|i| [0, 1, 2].map(|k| if (i >> k) & 1 == 1 { 2.0 } else { 0.0 })).collect();
        let triangles = vec![
            [0, 2, 1],
            [1, 2, 3],
            [4, 5, 6],
            [5, 7, 6],
            [0, 1, 4],
            [1, 5, 4],
            [2, 6, 3],
            [3, 6, 7],
            [0, 4, 2],
            [2, 4, 6],
            [1, 3, 5],
            [3, 7, 5],
        ];
        let crust = TriMesh { positions, triangles };
        let norm = Normalisation::of_mesh(&crust).unwrap();
        assert_eq!((norm.loc, norm.scale), ([1.0; 3], 2.0));
        // The inside site at the centre; outside sites 2 away along each axis: the cell of
        // the centre is the cube.
        let mut sites = vec![[1.0; 3]];
        for k in 0..3 {
            for s in [-1.0, 1.0] {
                let mut p = [1.0; 3];
                p[k] += 2.0 * s;
                sites.push(p);
            }
        }
        let inside: Vec<bool> = (0..sites.len()).map(|i| i == 0).collect();
        let spec = OccupancySpec { points: 1000, ..Default::default() };
        let s = occupancy_samples(&spec, norm, &crust, &sites, &inside, 7).unwrap();
        assert_eq!((s.points.len(), s.num_uniform), (1000, 500));
        for (p, &label) in s.points.iter().zip(&s.inside) {
            let u = p.map(f64::from);
            assert!(u.iter().all(|c| c.abs() <= 0.55 + 0.1), "{u:?}");
            let x = norm.to_input(u);
            let cube = x.iter().all(|&c| (0.0..=2.0).contains(&c));
            // The centre's cell is the cube (ties on its faces aside).
            if x.iter().all(|&c| (c - 1.0).abs() < 0.999) || !cube {
                assert_eq!(label, cube, "{x:?}");
            }
        }
        let near_in = s.inside[500..].iter().filter(|&&b| b).count();
        assert!((150..350).contains(&near_in), "near-surface points inside: {near_in} of 500");
        assert_eq!(occupancy_samples(&spec, norm, &crust, &sites, &inside, 7).unwrap(), s);

        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.points.npz");
        write_occupancy_samples(&path, &s).unwrap();
        let mut r = ndarray_npy::NpzReader::new(std::fs::File::open(&path).unwrap()).unwrap();
        let mut names = r.names().unwrap();
        names.sort();
        assert_eq!(names, ["loc", "occupancies", "points", "scale"]);
        let occ: Array1<u8> = r.by_name("occupancies").unwrap();
        assert_eq!(occ.to_vec(), packbits(&s.inside));
        let loc: Array1<f32> = r.by_name("loc").unwrap();
        assert_eq!(loc.to_vec(), vec![1.0; 3]);
        let scale: ndarray::Array0<f32> = r.by_name("scale").unwrap();
        assert_eq!(scale.into_scalar(), 2.0);
        // The points' header says float16, and their bytes are the stored values.
        let bytes = std::fs::read(&path).unwrap();
        assert!(bytes.windows(5).any(|w| w == b"'<f2'"));
        assert_eq!(dir.path().read_dir().unwrap().count(), 1, "no temporary file left");
    }
}
