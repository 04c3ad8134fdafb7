//! Pictures: the tSNE scatter, the latent interpolation (Voronoi diagrams beside OccNet
//! images), reconstructions, and the training curves; each as PNG and SVG.

use std::path::Path;

use plot::{Anchor, Drawing, Rgb, Shape, TextSize};

use crate::error::MnistError;
use crate::eval::decoded_grid;
use crate::model::{site_labels, Model, LATENT};
use crate::net::OccNetScratch;
use crate::train::CurvePoint;

/// Ten distinguishable class colours (Tableau 10).
pub const CLASS_COLORS: [Rgb; 10] = [
    Rgb(0x1f, 0x77, 0xb4),
    Rgb(0xff, 0x7f, 0x0e),
    Rgb(0x2c, 0xa0, 0x2c),
    Rgb(0xd6, 0x27, 0x28),
    Rgb(0x94, 0x67, 0xbd),
    Rgb(0x8c, 0x56, 0x4b),
    Rgb(0xe3, 0x77, 0xc2),
    Rgb(0x7f, 0x7f, 0x7f),
    Rgb(0xbc, 0xbd, 0x22),
    Rgb(0x17, 0xbe, 0xcf),
];

const BLACK: Rgb = Rgb(0, 0, 0);
const GREY: Rgb = Rgb(0x66, 0x66, 0x66);
const INSIDE_CELL: Rgb = Rgb(0xbf, 0xd7, 0xf0);
const OUTSIDE_CELL: Rgb = Rgb(0xf7, 0xf7, 0xf7);
const CELL_EDGE: Rgb = Rgb(0xc8, 0xc8, 0xc8);
const CRUST: Rgb = Rgb(0xc0, 0x1a, 0x1a);
const INSIDE_SITE: Rgb = Rgb(0x1f, 0x4e, 0x9a);
const OUTSIDE_SITE: Rgb = Rgb(0x99, 0x99, 0x99);

/// Writes `d` as `stem.png` and `stem.svg`.
///
/// # Errors
/// [`MnistError::Write`].
pub fn write_both(d: &Drawing, stem: &Path) -> Result<(), MnistError> {
    d.write_png(&stem.with_extension("png"))?;
    d.write_svg(&stem.with_extension("svg"))?;
    Ok(())
}

/// The tSNE scatter: one dot per code, coloured by class, with a legend.
pub fn tsne_drawing(points: &[[f64; 2]], classes: &[u8], title: &str) -> Drawing {
    let (w, h) = (900u32, 820u32);
    let mut d = Drawing::new(w, h);
    let (x0, y0, side) = (40.0, 60.0, 740.0);
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in points.iter().filter(|p| p[0].is_finite() && p[1].is_finite()) {
        for c in 0..2 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    }
    let span = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1e-12);
    let map = |p: [f64; 2]| {
        (
            x0 + (p[0] - lo[0] + 0.5 * (span - (hi[0] - lo[0]))) / span * side,
            y0 + (hi[1] - p[1] + 0.5 * (span - (hi[1] - lo[1]))) / span * side,
        )
    };
    d.push(Shape::Text {
        pos: (w as f64 / 2.0, 25.0),
        text: title.into(),
        size: TextSize::Title,
        anchor: Anchor::Middle,
        color: BLACK,
    });
    for (p, &c) in points.iter().zip(classes) {
        d.push(Shape::Disc { center: map(*p), radius: 1.6, fill: CLASS_COLORS[c as usize % 10] });
    }
    for (c, &fill) in CLASS_COLORS.iter().enumerate() {
        let y = 120.0 + 28.0 * c as f64;
        d.push(Shape::Disc { center: (820.0, y), radius: 7.0, fill });
        d.push(Shape::Text {
            pos: (836.0, y),
            text: c.to_string(),
            size: TextSize::Large,
            anchor: Anchor::Start,
            color: BLACK,
        });
    }
    d
}

/// Draws the Voronoi diagram of decoded `sites` into the square panel at `origin` of side
/// `side`: cells coloured by label, cell edges, the crust (exact 2D Delaunay, spade), sites.
pub fn voronoi_panel(d: &mut Drawing, sites: &[[f64; 2]], origin: (f64, f64), side: f64) {
    let labels = site_labels();
    let map = |p: [f64; 2]| (origin.0 + p[0] * side, origin.1 + p[1] * side);
    let Ok(diagram) = crust::planar::planar_diagram(sites, &labels, [0.0; 2], [1.0; 2]) else {
        d.push(Shape::Text {
            pos: (origin.0 + side / 2.0, origin.1 + side / 2.0),
            text: "invalid sites".into(),
            size: TextSize::Small,
            anchor: Anchor::Middle,
            color: CRUST,
        });
        return;
    };
    let mut rows: Vec<Vec<u32>> = vec![Vec::new(); sites.len()];
    for &(a, b) in &diagram.delaunay_edges {
        rows[a as usize].push(b);
        rows[b as usize].push(a);
    }
    for (i, row) in rows.iter().enumerate() {
        let poly = crust::planar::cell_polygon(sites, i, row.iter().copied(), [0.0; 2], [1.0; 2]);
        if poly.len() >= 3 {
            let fill = if labels[i] { INSIDE_CELL } else { OUTSIDE_CELL };
            d.push(Shape::Polygon { points: poly.iter().map(|&p| map(p)).collect(), fill });
        }
    }
    for e in &diagram.edges {
        d.push(Shape::Polyline { points: vec![map(e.segment[0]), map(e.segment[1])], width: 0.5, color: CELL_EDGE });
    }
    for c in &diagram.crust {
        d.push(Shape::Polyline { points: c.iter().map(|&p| map(p)).collect(), width: 1.8, color: CRUST });
    }
    for (p, &l) in sites.iter().zip(&labels) {
        if (0.0..=1.0).contains(&p[0]) && (0.0..=1.0).contains(&p[1]) {
            d.push(Shape::Disc { center: map(*p), radius: 1.3, fill: if l { INSIDE_SITE } else { OUTSIDE_SITE } });
        }
    }
    frame(d, origin, side);
}

fn frame(d: &mut Drawing, o: (f64, f64), s: f64) {
    d.push(Shape::Polyline {
        points: vec![o, (o.0 + s, o.1), (o.0 + s, o.1 + s), (o.0, o.1 + s), o],
        width: 1.0,
        color: GREY,
    });
}

/// An occupancy grid (`n × n`, row-major) as a grey picture: inside black.
pub fn occupancy_panel(d: &mut Drawing, grid: &[bool], n: usize, origin: (f64, f64), side: f64) {
    let values = grid.iter().map(|&b| if b { 20 } else { 255 }).collect();
    d.push(Shape::Gray { origin, size: (side, side), cols: n, rows: n, values });
    frame(d, origin, side);
}

/// An input image (intensity, dark = ink).
pub fn image_panel(d: &mut Drawing, pixels: &[u8], rows: usize, cols: usize, origin: (f64, f64), side: f64) {
    let values = pixels.iter().map(|&v| 255 - v).collect();
    d.push(Shape::Gray { origin, size: (side, side), cols, rows, values });
    frame(d, origin, side);
}

/// A row's name at the left edge.
fn row_label(d: &mut Drawing, y: f64, text: String) {
    d.push(Shape::Text { pos: (10.0, y), text, size: TextSize::Normal, anchor: Anchor::Start, color: BLACK });
}

/// One interpolation: the two input digits at the ends, and `steps` codes from one to the
/// other decoded by the Voronoi model (top row, diagrams) and the OccNet model (bottom
/// row, occupancy at 4× resolution), each model with its own encoder.
pub struct Interpolation<'a> {
    /// The row's title.
    pub title: String,
    /// The first digit's pixels and class.
    pub a: (&'a [u8], u8),
    /// The last digit's pixels and class.
    pub b: (&'a [u8], u8),
    /// Rows per image.
    pub rows: usize,
    /// Columns per image.
    pub cols: usize,
}

/// The interpolation figure for several pairs.
pub fn interpolation_drawing(voronoi: &Model, occnet: &Model, pairs: &[Interpolation], steps: usize) -> Drawing {
    let panel = 110.0;
    let gap = 8.0;
    let left = 130.0;
    let width = left + (steps as f64 + 2.0) * (panel + gap) + 20.0;
    let block = 2.0 * (panel + gap) + 50.0;
    let height = 50.0 + pairs.len() as f64 * block;
    let mut d = Drawing::new(width.ceil() as u32, height.ceil() as u32);
    d.push(Shape::Text {
        pos: (width / 2.0, 22.0),
        text: format!(
            "Latent interpolation in {steps} steps: {} (top, sites and crust) and {} (bottom)",
            voronoi.method.label(),
            occnet.method.label()
        ),
        size: TextSize::Title,
        anchor: Anchor::Middle,
        color: BLACK,
    });
    let mut scratch: Option<OccNetScratch> = None;
    for (pi, pair) in pairs.iter().enumerate() {
        let y0 = 50.0 + pi as f64 * block;
        d.push(Shape::Text {
            pos: (10.0, y0 + 12.0),
            text: pair.title.clone(),
            size: TextSize::Large,
            anchor: Anchor::Start,
            color: BLACK,
        });
        let y_top = y0 + 30.0;
        let y_bot = y_top + panel + gap;
        for (y, m) in [(y_top, voronoi), (y_bot, occnet)] {
            row_label(&mut d, y + panel / 2.0, m.method.label());
        }
        // Inputs at both ends.
        let xa = left;
        let xb = left + (steps as f64 + 1.0) * (panel + gap);
        for (x, img) in [(xa, pair.a.0), (xb, pair.b.0)] {
            image_panel(&mut d, img, pair.rows, pair.cols, (x, y_top), panel);
            image_panel(&mut d, img, pair.rows, pair.cols, (x, y_bot), panel);
        }
        let enc = |m: &Model| m.encode(&[pair.a.0, pair.b.0]);
        let (cv, co) = (enc(voronoi), enc(occnet));
        for s in 0..steps {
            let t = if steps > 1 { s as f64 / (steps - 1) as f64 } else { 0.0 };
            let lerp = |c: &[f32]| -> Vec<f32> {
                (0..LATENT).map(|k| ((1.0 - t) * f64::from(c[k]) + t * f64::from(c[LATENT + k])) as f32).collect()
            };
            let x = left + (s as f64 + 1.0) * (panel + gap);
            if let Ok(mut sites) = voronoi.decode_sites(&lerp(&cv)) {
                voronoi_panel(&mut d, &sites.remove(0), (x, y_top), panel);
            }
            let n = 4 * pair.rows.max(pair.cols);
            let grid = decoded_grid(occnet, &lerp(&co), n, &mut scratch);
            occupancy_panel(&mut d, &grid, n, (x, y_bot), panel);
            d.push(Shape::Text {
                pos: (x + panel / 2.0, y_bot + panel + 12.0),
                text: format!("t = {t:.2}"),
                size: TextSize::Small,
                anchor: Anchor::Middle,
                color: GREY,
            });
        }
    }
    d
}

/// Reconstructions of test digits: input, each model's decoded shape (Voronoi models as
/// diagrams, OccNet models as occupancy), one column per digit.
pub fn reconstructions_drawing(models: &[&Model], digits: &[(&[u8], u8)], rows: usize, cols: usize) -> Drawing {
    let panel = 100.0;
    let gap = 6.0;
    let left = 120.0;
    let width = left + digits.len() as f64 * (panel + gap) + 10.0;
    let height = 40.0 + (models.len() as f64 + 1.0) * (panel + gap) + 10.0;
    let mut d = Drawing::new(width.ceil() as u32, height.ceil() as u32);
    d.push(Shape::Text {
        pos: (width / 2.0, 20.0),
        text: "Test digits and their reconstructions".into(),
        size: TextSize::Title,
        anchor: Anchor::Middle,
        color: BLACK,
    });
    let mut scratch: Option<OccNetScratch> = None;
    let imgs: Vec<&[u8]> = digits.iter().map(|d| d.0).collect();
    row_label(&mut d, 40.0 + panel / 2.0, "input".into());
    for (j, (img, _)) in digits.iter().enumerate() {
        image_panel(&mut d, img, rows, cols, (left + j as f64 * (panel + gap), 40.0), panel);
    }
    for (mi, m) in models.iter().enumerate() {
        let y = 40.0 + (mi as f64 + 1.0) * (panel + gap);
        row_label(&mut d, y + panel / 2.0, m.method.label());
        let codes = m.encode(&imgs);
        for j in 0..digits.len() {
            let code = &codes[j * LATENT..(j + 1) * LATENT];
            let x = left + j as f64 * (panel + gap);
            match m.decode_sites(code) {
                Ok(mut s) => voronoi_panel(&mut d, &s.remove(0), (x, y), panel),
                Err(_) => {
                    let n = 4 * rows.max(cols);
                    let g = decoded_grid(m, code, n, &mut scratch);
                    occupancy_panel(&mut d, &g, n, (x, y), panel);
                }
            }
        }
    }
    d
}

/// The training curves (mean loss per epoch; each method's own loss) on a log axis.
pub fn curves_chart(curves: &[(String, Vec<CurvePoint>)]) -> plot::Chart {
    plot::Chart {
        title: "MNIST autoencoders: training loss per epoch (Voronoi: soft-Voronoi L1 + regularisers; OccNet: cross-entropy)".into(),
        x_label: "epoch".into(),
        y_label: "mean training loss".into(),
        log_x: false,
        log_y: true,
        series: curves
            .iter()
            .map(|(name, c)| plot::Series { name: name.clone(), points: c.iter().map(|p| (p.epoch as f64, p.loss)).collect(), band: None })
            .collect(),
    }
}
