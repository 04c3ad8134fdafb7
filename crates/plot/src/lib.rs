//! Small line charts for the project's studies, written as SVG and PNG in pure Rust.
//!
//! A [`Chart`] holds a title, two axis labels, the axis kinds (linear or log10) and one
//! [`Series`] per method. Each series gets a colour from the colour-blind safe Okabe–Ito
//! palette ([`series_color`]) *and* its own marker shape ([`series_marker`]), so lines stay
//! distinguishable in greyscale too. Ranges are automatic with some padding; log axes get
//! decade ticks labelled 10^k, with 2..9 minor grid lines; an optional per-point interval
//! ([`Series::band`]) is drawn as a vertical error bar.
//!
//! Values that cannot be shown (non-finite, or non-positive on a log axis) are skipped and
//! break the line there; nothing panics. A chart with nothing to show is an error
//! ([`PlotError::NoData`]) for the fallible methods.
//!
//! ```no_run
//! # fn main() -> Result<(), plot::PlotError> {
//! let chart = plot::Chart {
//!     title: "Sphere of radius 0.35: Hausdorff distance vs parameters".into(),
//!     x_label: "parameters".into(),
//!     y_label: "Hausdorff distance (unit cube)".into(),
//!     log_x: true,
//!     log_y: true,
//!     series: vec![plot::Series {
//!         name: "Voronoi (3K)".into(),
//!         points: vec![(24.0, 0.1), (96.0, 0.03)],
//!         band: Some(vec![(0.08, 0.12), (0.025, 0.035)]),
//!     }],
//! };
//! chart.write_svg(std::path::Path::new("out.svg"))?;
//! chart.write_png(std::path::Path::new("out.png"))?;
//! # Ok(()) }
//! ```

pub mod drawing;
mod layout;
mod raster;
pub mod raster3d;
mod svg;
pub mod ticks;

use std::path::Path;

pub use drawing::{Anchor, Drawing, Shape, TextSize};
pub use ticks::{linear_ticks, log_ticks, Ticks};

/// Default picture width in pixels (SVG user units and PNG pixels).
pub const WIDTH: u32 = 1200;
/// Default picture height in pixels.
pub const HEIGHT: u32 = 800;
/// Smallest PNG size [`Chart::to_png_sized`] accepts.
pub const MIN_SIZE: (u32, u32) = (400, 300);
/// Largest PNG size [`Chart::to_png_sized`] accepts.
pub const MAX_SIZE: (u32, u32) = (4000, 4000);

/// A line chart: one line (with markers and optional error bars) per series.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Chart {
    /// Centred above the plot; empty for none.
    pub title: String,
    /// Under the horizontal axis; empty for none.
    pub x_label: String,
    /// Beside the vertical axis, rotated; empty for none.
    pub y_label: String,
    /// Logarithmic (base 10) horizontal axis.
    pub log_x: bool,
    /// Logarithmic (base 10) vertical axis.
    pub log_y: bool,
    /// The lines, drawn in this order and listed in this order in the legend.
    pub series: Vec<Series>,
}

/// One line of a chart.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Series {
    /// Legend entry.
    pub name: String,
    /// `(x, y)` points, joined in the given order. A point that cannot be shown (non-finite,
    /// or non-positive on a log axis) is skipped and breaks the line.
    pub points: Vec<(f64, f64)>,
    /// Optional `(low, high)` interval of `y` for each point, drawn as a vertical error bar;
    /// must have one entry per point. An entry with a NaN is skipped; an end that is
    /// infinite or (on a log axis) non-positive runs to the edge of the plot.
    pub band: Option<Vec<(f64, f64)>>,
}

/// What went wrong while making or writing a chart.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// Nothing to draw: no series, or no point with showable coordinates.
    #[error("nothing to plot: {0}")]
    NoData(String),
    /// A series' `band` does not have one entry per point.
    #[error("series {series:?} has {band} error-bar intervals for {points} points")]
    BandLength {
        /// The series' name.
        series: String,
        /// Number of points.
        points: usize,
        /// Number of intervals.
        band: usize,
    },
    /// The requested raster size is outside [`MIN_SIZE`]..=[`MAX_SIZE`].
    #[error("image size {width}x{height} is outside 400x300..=4000x4000")]
    Size {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
    },
    /// The PNG encoder failed.
    #[error("PNG encoding failed: {0}")]
    Png(String),
    /// The output file could not be written (nothing was left behind).
    #[error(transparent)]
    Write(#[from] mesh_io::MeshError),
}

/// An sRGB colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Rgb(pub u8, pub u8, pub u8);

impl Rgb {
    /// `#rrggbb`.
    pub fn hex(self) -> String {
        format!("#{:02x}{:02x}{:02x}", self.0, self.1, self.2)
    }
}

/// The Okabe–Ito colour-blind safe palette, reordered so the colours that read best on
/// white come first (yellow last). Series `i` uses `PALETTE[i % 8]`.
pub const PALETTE: [Rgb; 8] = [
    Rgb(0x00, 0x72, 0xB2), // blue
    Rgb(0xD5, 0x5E, 0x00), // vermillion
    Rgb(0x00, 0x9E, 0x73), // bluish green
    Rgb(0xCC, 0x79, 0xA7), // reddish purple
    Rgb(0xE6, 0x9F, 0x00), // orange
    Rgb(0x56, 0xB4, 0xE9), // sky blue
    Rgb(0x00, 0x00, 0x00), // black
    Rgb(0xF0, 0xE4, 0x42), // yellow
];

/// Marker shapes; series `i` uses `MARKERS[i % 7]`, so colour and shape pairs repeat only
/// after 56 series.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Marker {
    /// Filled disc.
    Circle,
    /// Filled square.
    Square,
    /// Filled triangle pointing up.
    TriangleUp,
    /// Filled diamond.
    Diamond,
    /// Filled triangle pointing down.
    TriangleDown,
    /// Diagonal cross (stroked).
    Cross,
    /// Upright plus (stroked).
    Plus,
}

/// The marker cycle, see [`Marker`].
pub const MARKERS: [Marker; 7] = [
    Marker::Circle,
    Marker::Square,
    Marker::TriangleUp,
    Marker::Diamond,
    Marker::TriangleDown,
    Marker::Cross,
    Marker::Plus,
];

/// Colour of the `i`-th series.
pub fn series_color(i: usize) -> Rgb {
    PALETTE[i % PALETTE.len()]
}

/// Marker of the `i`-th series.
pub fn series_marker(i: usize) -> Marker {
    MARKERS[i % MARKERS.len()]
}

impl Chart {
    /// Check that the chart has something to draw and consistent error bars.
    ///
    /// # Errors
    /// [`PlotError::NoData`] if there is no series or no showable point;
    /// [`PlotError::BandLength`] if a band's length differs from its series' point count.
    pub fn validate(&self) -> Result<(), PlotError> {
        if self.series.is_empty() {
            return Err(PlotError::NoData("the chart has no series".into()));
        }
        for s in &self.series {
            if let Some(band) = &s.band {
                if band.len() != s.points.len() {
                    return Err(PlotError::BandLength {
                        series: s.name.clone(),
                        points: s.points.len(),
                        band: band.len(),
                    });
                }
            }
        }
        let showable = self
            .series
            .iter()
            .flat_map(|s| &s.points)
            .any(|&(x, y)| layout::showable(x, self.log_x) && layout::showable(y, self.log_y));
        if !showable {
            let what = match (self.log_x, self.log_y) {
                (false, false) => "finite",
                (true, false) => "finite, with positive x (log axis),",
                (false, true) => "finite, with positive y (log axis),",
                (true, true) => "finite and positive (log axes)",
            };
            return Err(PlotError::NoData(format!("no point is {what} in any series")));
        }
        Ok(())
    }

    /// The chart as an SVG document of [`WIDTH`]×[`HEIGHT`] user units.
    ///
    /// Never fails: a chart with nothing to show yields empty axes with a "no data" note,
    /// and surplus error-bar intervals are ignored. Use [`Chart::try_to_svg`] to get an
    /// error instead.
    pub fn to_svg(&self) -> String {
        svg::render(&layout::Layout::new(self, f64::from(WIDTH), f64::from(HEIGHT)))
    }

    /// [`Chart::to_svg`] after [`Chart::validate`].
    ///
    /// # Errors
    /// As [`Chart::validate`].
    pub fn try_to_svg(&self) -> Result<String, PlotError> {
        self.validate()?;
        Ok(self.to_svg())
    }

    /// The chart as PNG bytes of [`WIDTH`]×[`HEIGHT`] pixels (8-bit RGB).
    ///
    /// # Errors
    /// As [`Chart::validate`], or [`PlotError::Png`].
    pub fn to_png(&self) -> Result<Vec<u8>, PlotError> {
        self.to_png_sized(WIDTH, HEIGHT)
    }

    /// The chart as PNG bytes of `width`×`height` pixels. Text uses fixed bitmap fonts, so
    /// a larger picture shows more room, not larger letters.
    ///
    /// # Errors
    /// As [`Chart::validate`]; [`PlotError::Size`] outside [`MIN_SIZE`]..=[`MAX_SIZE`];
    /// [`PlotError::Png`].
    pub fn to_png_sized(&self, width: u32, height: u32) -> Result<Vec<u8>, PlotError> {
        if width < MIN_SIZE.0 || height < MIN_SIZE.1 || width > MAX_SIZE.0 || height > MAX_SIZE.1 {
            return Err(PlotError::Size { width, height });
        }
        self.validate()?;
        let layout = layout::Layout::new(self, f64::from(width), f64::from(height));
        let rgb = raster::render(&layout, width, height);
        raster::encode_png(&rgb, width, height)
    }

    /// Write [`Chart::to_svg`] to `path` atomically (temporary file, then rename).
    ///
    /// # Errors
    /// As [`Chart::validate`] (checked before the file is touched), or
    /// [`PlotError::Write`].
    pub fn write_svg(&self, path: &Path) -> Result<(), PlotError> {
        write_atomic(path, self.try_to_svg()?.as_bytes())
    }

    /// Write [`Chart::to_png`] (1200×800) to `path` atomically.
    ///
    /// # Errors
    /// As [`Chart::to_png`] (checked before the file is touched), or [`PlotError::Write`].
    pub fn write_png(&self, path: &Path) -> Result<(), PlotError> {
        write_atomic(path, &self.to_png()?)
    }
}

/// Writes `bytes` to `path` atomically (temporary file, then rename): every picture of
/// this crate goes through here.
pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), PlotError> {
    mesh_io::atomic_write(path, |w| w.write_all(bytes))?;
    Ok(())
}
