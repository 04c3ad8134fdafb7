//! A small software rasterizer for pictures of meshes: several meshes (rows) seen from
//! several directions (columns), flat-shaded, in one RGB image.
//!
//! Written here rather than taken from a crate: what it needs is a z-buffer, an
//! orthographic camera, two directional lights and a silhouette line — a few hundred lines —
//! while the rendering crates (three-d, kiss3d, wgpu, tiny-skia + a 3D layer) bring a GPU
//! stack or many dependencies to a workspace that builds on 2 cores. Text uses the
//! bitmap fonts of `embedded-graphics` and PNG the `png` encoder, both already here.
//!
//! - **Camera**: orthographic, +Y up (the glTF convention; [`Up::Z`] for CAD exports
//!   that are Z-up). A [`View`] is an azimuth around the up axis and an elevation above
//!   the horizontal plane. All rows share one scale and centre per column, so the input
//!   and the crust are drawn at the same size and place.
//! - **Shading**: flat (one colour per triangle: faceted surfaces look faceted), Lambert
//!   with a key and a fill light fixed to the camera, plus ambient. Triangles seen from
//!   behind (holes, inverted orientation, the inside of an open mesh) get
//!   [`BACK_FACE`], so orientation problems show.
//! - **Anti-aliasing**: drawn at [`SUPERSAMPLE`]× and averaged down; a dark line marks the
//!   silhouette and depth jumps.
//! - Deterministic (sequential, fixed order: the same input gives the same bytes), never
//!   panics: non-finite vertices and zero-area triangles are skipped, an empty mesh gives
//!   an empty cell with a note, and only a call with no model at all is an error.

use std::convert::Infallible;
use std::path::Path;

use embedded_graphics::mono_font::iso_8859_1::{FONT_7X13, FONT_9X18_BOLD};
use embedded_graphics::mono_font::MonoTextStyle;
use embedded_graphics::pixelcolor::Rgb888;
use embedded_graphics::prelude::*;
use embedded_graphics::text::{Alignment, Baseline, Text, TextStyleBuilder};
use mesh_io::TriMesh;
use vf_common::vec3::{cross, dot, sub};

use crate::{PlotError, Rgb};

/// Supersampling factor (per axis).
pub const SUPERSAMPLE: u32 = 2;
/// Colour of triangles seen from behind.
pub const BACK_FACE: Rgb = Rgb(0xD5, 0x5E, 0x00);
/// Default colour of the input mesh (warm grey).
pub const INPUT_COLOR: Rgb = Rgb(0xC8, 0xC2, 0xB8);
/// Default colour of the crust (Okabe–Ito sky blue).
pub const CRUST_COLOR: Rgb = Rgb(0x56, 0xB4, 0xE9);
/// Smallest and largest cell side in pixels.
pub const CELL_RANGE: (u32, u32) = (64, 2000);

const BG_TOP: [f64; 3] = [250.0, 251.0, 252.0];
const BG_BOTTOM: [f64; 3] = [222.0, 227.0, 233.0];
const OUTLINE: [u8; 3] = [40, 44, 52];
const SEPARATOR: [u8; 3] = [190, 195, 202];
const TEXT: Rgb888 = Rgb888::new(30, 33, 40);
const GREY_TEXT: Rgb888 = Rgb888::new(95, 100, 110);
/// Height of the caption band at the top of each cell, and of the title band.
const CAPTION_H: u32 = 20;
const TITLE_H: u32 = 28;

/// Which world axis points up in the picture.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Up {
    /// +Y up (glTF, most OBJ and PLY files).
    #[default]
    Y,
    /// +Z up (many CAD and STL exports).
    Z,
}

/// A viewing direction: the camera sits at `azimuth_deg` around the up axis (0 = looking
/// along −Z at the front, i.e. from +Z for [`Up::Y`]) and `elevation_deg` above the
/// horizontal plane (clamped to ±85°).
#[derive(Debug, Clone, PartialEq)]
pub struct View {
    /// Shown in the cell's caption.
    pub name: String,
    /// Degrees around the up axis, counter-clockwise seen from above.
    pub azimuth_deg: f64,
    /// Degrees above the horizontal plane.
    pub elevation_deg: f64,
}

impl View {
    /// A view named `name`.
    pub fn new(name: &str, azimuth_deg: f64, elevation_deg: f64) -> View {
        View { name: name.into(), azimuth_deg, elevation_deg }
    }

    /// Front three-quarter, back three-quarter and from above: the main job's picture.
    pub fn defaults() -> Vec<View> {
        vec![View::new("front", 30.0, 20.0), View::new("back", 210.0, 20.0), View::new("top", 0.0, 75.0)]
    }
}

/// One mesh to draw (one row of the picture).
#[derive(Debug, Clone)]
pub struct Model<'a> {
    /// Shown in the caption of each of its cells (e.g. "input" or "crust").
    pub label: String,
    /// The triangles; counter-clockwise seen from outside is drawn in `color`, the other
    /// side in [`BACK_FACE`].
    pub mesh: &'a TriMesh,
    /// Base colour of front faces.
    pub color: Rgb,
}

/// How to lay out the picture.
#[derive(Debug, Clone)]
pub struct Options {
    /// Columns.
    pub views: Vec<View>,
    /// Width and height of one cell in pixels (each within [`CELL_RANGE`]).
    pub cell: (u32, u32),
    /// One line above the grid; empty for none.
    pub title: String,
    /// The up axis.
    pub up: Up,
}

impl Default for Options {
    fn default() -> Options {
        Options { views: View::defaults(), cell: (400, 400), title: String::new(), up: Up::Y }
    }
}

/// An 8-bit RGB picture.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major RGB triples, top row first.
    pub rgb: Vec<u8>,
}

impl Image {
    /// The pixel at `(x, y)`.
    ///
    /// # Panics
    /// If `(x, y)` is outside the image.
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 3] {
        let i = (y as usize * self.width as usize + x as usize) * 3;
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }

    /// PNG bytes.
    ///
    /// # Errors
    /// [`PlotError::Png`].
    pub fn to_png(&self) -> Result<Vec<u8>, PlotError> {
        crate::raster::encode_png(&self.rgb, self.width, self.height)
    }

    /// Write the PNG to `path` atomically (temporary file beside it, then rename).
    ///
    /// # Errors
    /// [`PlotError::Png`] (before the file is touched) or [`PlotError::Write`].
    pub fn write_png(&self, path: &Path) -> Result<(), PlotError> {
        crate::write_atomic(path, &self.to_png()?)
    }
}

/// The camera of one column: an orthonormal basis (right, up, towards the viewer).
#[derive(Debug, Clone, Copy)]
struct Camera {
    x: [f64; 3],
    y: [f64; 3],
    z: [f64; 3],
}

/// a / |a|, or zero for a zero or non-finite length.
fn normalize(a: [f64; 3]) -> [f64; 3] {
    let n = dot(a, a).sqrt();
    if n > 0.0 && n.is_finite() {
        [a[0] / n, a[1] / n, a[2] / n]
    } else {
        [0.0; 3]
    }
}

impl Camera {
    fn new(view: &View, up: Up) -> Camera {
        let az = view.azimuth_deg.to_radians();
        let el = view.elevation_deg.clamp(-85.0, 85.0).to_radians();
        // In a Y-up frame: towards the viewer, then right = up × z, y = z × x.
        let (z, x) = {
            let z = [az.sin() * el.cos(), el.sin(), az.cos() * el.cos()];
            let x = normalize(cross([0.0, 1.0, 0.0], z));
            (z, x)
        };
        let y = cross(z, x);
        match up {
            Up::Y => Camera { x, y, z },
            // Z-up: rotate the Y-up basis by +90° about X, (a, b, c) ↦ (a, −c, b), so the
            // frame's up (+Y) becomes the world's +Z and its front (+Z) the world's −Y.
            Up::Z => {
                let m = |v: [f64; 3]| [v[0], -v[2], v[1]];
                Camera { x: m(x), y: m(y), z: m(z) }
            }
        }
    }

    fn project(&self, p: [f64; 3]) -> [f64; 3] {
        [dot(p, self.x), dot(p, self.y), dot(p, self.z)]
    }
}

/// A supersampled cell: colour, depth (larger is nearer), coverage.
struct Cell {
    w: usize,
    h: usize,
    rgb: Vec<[f64; 3]>,
    depth: Vec<f64>,
}

impl Cell {
    fn new(w: usize, h: usize) -> Cell {
        let mut rgb = Vec::with_capacity(w * h);
        for y in 0..h {
            let t = y as f64 / (h.max(2) - 1) as f64;
            let c = [0, 1, 2].map(|i| BG_TOP[i] + (BG_BOTTOM[i] - BG_TOP[i]) * t);
            rgb.extend(std::iter::repeat_n(c, w));
        }
        Cell { w, h, rgb, depth: vec![f64::NEG_INFINITY; w * h] }
    }

    /// Fill the triangle with screen corners `s` (x, y in pixels, z depth) in `color`.
    fn triangle(&mut self, s: [[f64; 3]; 3], color: [f64; 3]) {
        let edge =
            |a: [f64; 3], b: [f64; 3], px: f64, py: f64| (b[0] - a[0]) * (py - a[1]) - (b[1] - a[1]) * (px - a[0]);
        let area = edge(s[0], s[1], s[2][0], s[2][1]);
        if area == 0.0 || !area.is_finite() {
            return;
        }
        let xmin = s.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min).floor().max(0.0);
        let xmax = s.iter().map(|p| p[0]).fold(f64::NEG_INFINITY, f64::max).ceil().min(self.w as f64 - 1.0);
        let ymin = s.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min).floor().max(0.0);
        let ymax = s.iter().map(|p| p[1]).fold(f64::NEG_INFINITY, f64::max).ceil().min(self.h as f64 - 1.0);
        if xmin > xmax || ymin > ymax {
            return;
        }
        for y in ymin as usize..=ymax as usize {
            let py = y as f64 + 0.5;
            for x in xmin as usize..=xmax as usize {
                let px = x as f64 + 0.5;
                let w0 = edge(s[1], s[2], px, py) / area;
                let w1 = edge(s[2], s[0], px, py) / area;
                let w2 = edge(s[0], s[1], px, py) / area;
                if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                    continue;
                }
                let z = w0 * s[0][2] + w1 * s[1][2] + w2 * s[2][2];
                let i = y * self.w + x;
                if z > self.depth[i] {
                    self.depth[i] = z;
                    self.rgb[i] = color;
                }
            }
        }
    }

    /// Dark line where coverage ends or depth jumps by more than `jump`.
    fn outline(&mut self, jump: f64) {
        let (w, h) = (self.w, self.h);
        let mut edge = vec![false; w * h];
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                let d = self.depth[i];
                if d == f64::NEG_INFINITY {
                    continue;
                }
                let mut hit = false;
                for (dx, dy) in [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)] {
                    let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                    if nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                        continue;
                    }
                    let dn = self.depth[ny as usize * w + nx as usize];
                    // Only the far side of a jump draws, so the line stays one pixel wide.
                    if dn == f64::NEG_INFINITY || d - dn > jump {
                        hit = true;
                    }
                }
                edge[i] = hit;
            }
        }
        for (i, e) in edge.into_iter().enumerate() {
            if e {
                self.rgb[i] = OUTLINE.map(f64::from);
            }
        }
    }
}

/// Key and fill light (camera frame) and ambient: the intensity of a face with unit
/// camera-frame normal `n` (facing the viewer).
fn lambert(n: [f64; 3]) -> f64 {
    let key = normalize([-0.45, 0.6, 0.65]);
    let fill = normalize([0.7, -0.1, 0.7]);
    (0.25 + 0.62 * dot(n, key).max(0.0) + 0.22 * dot(n, fill).max(0.0)).min(1.05)
}

/// Draw `models` (rows) from `options.views` (columns), flat-shaded, into one image.
///
/// # Errors
/// [`PlotError::NoData`] when `models` or `options.views` is empty; [`PlotError::Size`]
/// when a cell side is outside [`CELL_RANGE`].
pub fn render(models: &[Model], options: &Options) -> Result<Image, PlotError> {
    if models.is_empty() {
        return Err(PlotError::NoData("no mesh to draw".into()));
    }
    if options.views.is_empty() {
        return Err(PlotError::NoData("no view to draw from".into()));
    }
    let (cw, ch) = options.cell;
    if !(CELL_RANGE.0..=CELL_RANGE.1).contains(&cw) || !(CELL_RANGE.0..=CELL_RANGE.1).contains(&ch) {
        return Err(PlotError::Size { width: cw, height: ch });
    }
    let title_h = if options.title.is_empty() { 0 } else { TITLE_H };
    let width = cw * options.views.len() as u32;
    let height = title_h + ch * models.len() as u32;
    let mut image = Image { width, height, rgb: vec![255; width as usize * height as usize * 3] };

    // One centre for everything: the middle of the finite vertices' bounding box.
    let finite = |p: &[f64; 3]| p.iter().all(|c| c.is_finite());
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for m in models {
        for t in &m.mesh.triangles {
            for &v in t {
                if let Some(p) = m.mesh.positions.get(v as usize).filter(|p| finite(p)) {
                    for k in 0..3 {
                        lo[k] = lo[k].min(p[k]);
                        hi[k] = hi[k].max(p[k]);
                    }
                }
            }
        }
    }
    let any = lo[0] <= hi[0];
    let center = if any { [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k])) } else { [0.0; 3] };
    let radius = if any { 0.5 * dot(sub(hi, lo), sub(hi, lo)).sqrt() } else { 0.0 };

    let k = SUPERSAMPLE as usize;
    let (bw, bh) = (cw as usize * k, (ch - CAPTION_H) as usize * k);
    for (col, view) in options.views.iter().enumerate() {
        let cam = Camera::new(view, options.up);
        // Vertices in the camera frame, per model; the column's scale fits them all.
        let projected: Vec<Vec<[f64; 3]>> = models
            .iter()
            .map(|m| {
                m.mesh
                    .positions
                    .iter()
                    .map(|&p| if finite(&p) { cam.project(sub(p, center)) } else { [f64::NAN; 3] })
                    .collect()
            })
            .collect();
        let (mut xl, mut xh, mut yl, mut yh) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
        for (m, pr) in models.iter().zip(&projected) {
            for t in &m.mesh.triangles {
                for &v in t {
                    if let Some(q) = pr.get(v as usize).filter(|q| q[0].is_finite()) {
                        (xl, xh, yl, yh) = (xl.min(q[0]), xh.max(q[0]), yl.min(q[1]), yh.max(q[1]));
                    }
                }
            }
        }
        let margin = 0.06;
        let scale = {
            let sx = bw as f64 * (1.0 - 2.0 * margin) / (xh - xl);
            let sy = bh as f64 * (1.0 - 2.0 * margin) / (yh - yl);
            let s = sx.min(sy);
            if s.is_finite() && s > 0.0 {
                s
            } else {
                1.0
            }
        };
        let (mx, my) = if xl <= xh { (0.5 * (xl + xh), 0.5 * (yl + yh)) } else { (0.0, 0.0) };
        let screen = |q: [f64; 3]| [bw as f64 * 0.5 + scale * (q[0] - mx), bh as f64 * 0.5 - scale * (q[1] - my), q[2]];
        for (row, (m, pr)) in models.iter().zip(&projected).enumerate() {
            let mut cell = Cell::new(bw, bh);
            let base = [m.color.0, m.color.1, m.color.2].map(f64::from);
            let back = [BACK_FACE.0, BACK_FACE.1, BACK_FACE.2].map(f64::from);
            let mut drawn = 0usize;
            for t in &m.mesh.triangles {
                let Some(q) = t
                    .iter()
                    .map(|&v| pr.get(v as usize).copied().filter(|q| q[0].is_finite()))
                    .collect::<Option<Vec<_>>>()
                else {
                    continue;
                };
                let n = normalize(cross(sub(q[1], q[0]), sub(q[2], q[0])));
                if n == [0.0; 3] {
                    continue;
                }
                let (n, color) = if n[2] >= 0.0 { (n, base) } else { (n.map(|c| -c), back) };
                let i = lambert(n);
                cell.triangle([screen(q[0]), screen(q[1]), screen(q[2])], color.map(|c| (c * i).min(255.0)));
                drawn += 1;
            }
            cell.outline(0.04 * radius);
            // Average down into the image.
            let (ox, oy) = (col * cw as usize, title_h as usize + row * ch as usize + CAPTION_H as usize);
            for y in 0..bh / k {
                for x in 0..bw / k {
                    let mut acc = [0.0; 3];
                    for dy in 0..k {
                        for dx in 0..k {
                            let c = cell.rgb[(y * k + dy) * bw + x * k + dx];
                            (0..3).for_each(|i| acc[i] += c[i]);
                        }
                    }
                    let o = ((oy + y) * width as usize + ox + x) * 3;
                    for (px, a) in image.rgb[o..o + 3].iter_mut().zip(acc) {
                        *px = (a / (k * k) as f64).round().clamp(0.0, 255.0) as u8;
                    }
                }
            }
            let caption = format!("{} \u{b7} {}", m.label, view.name);
            let note = if drawn == 0 { Some("no triangles to draw") } else { None };
            captions(&mut image, (ox as i32, (oy - CAPTION_H as usize) as i32), (cw, ch), &caption, note);
        }
    }
    // Cell separators.
    for c in 1..options.views.len() as u32 {
        for y in title_h..height {
            image.set(c * cw, y, SEPARATOR);
        }
    }
    for r in 1..models.len() as u32 {
        for x in 0..width {
            image.set(x, title_h + r * ch, SEPARATOR);
        }
    }
    if title_h > 0 {
        let style = MonoTextStyle::new(&FONT_9X18_BOLD, TEXT);
        let text = crate::layout::truncate(&options.title, (width as usize).saturating_sub(16) / 9);
        let _ =
            Text::with_baseline(&text, Point::new(8, (TITLE_H / 2) as i32), style, Baseline::Middle).draw(&mut image);
        for x in 0..width {
            image.set(x, title_h - 1, SEPARATOR);
        }
    }
    Ok(image)
}

/// The caption band of a cell and, for an empty cell, a note in its middle.
fn captions(image: &mut Image, origin: (i32, i32), cell: (u32, u32), caption: &str, note: Option<&str>) {
    for y in 0..CAPTION_H {
        for x in 0..cell.0 {
            image.set(origin.0 as u32 + x, origin.1 as u32 + y, [255, 255, 255]);
        }
    }
    let style = MonoTextStyle::new(&FONT_7X13, TEXT);
    let text = crate::layout::truncate(caption, (cell.0 as usize).saturating_sub(12) / 7);
    let _ =
        Text::with_baseline(&text, Point::new(origin.0 + 6, origin.1 + CAPTION_H as i32 / 2), style, Baseline::Middle)
            .draw(image);
    if let Some(note) = note {
        let style = MonoTextStyle::new(&FONT_7X13, GREY_TEXT);
        let centred = TextStyleBuilder::new().alignment(Alignment::Center).baseline(Baseline::Middle).build();
        let at = Point::new(origin.0 + cell.0 as i32 / 2, origin.1 + cell.1 as i32 / 2);
        let _ = Text::with_text_style(note, at, style, centred).draw(image);
    }
}

impl Image {
    fn set(&mut self, x: u32, y: u32, c: [u8; 3]) {
        if x < self.width && y < self.height {
            let i = (y as usize * self.width as usize + x as usize) * 3;
            self.rgb[i..i + 3].copy_from_slice(&c);
        }
    }
}

impl OriginDimensions for Image {
    fn size(&self) -> Size {
        Size::new(self.width, self.height)
    }
}

impl DrawTarget for Image {
    type Color = Rgb888;
    type Error = Infallible;

    fn draw_iter<I: IntoIterator<Item = Pixel<Rgb888>>>(&mut self, pixels: I) -> Result<(), Infallible> {
        for Pixel(p, c) in pixels {
            if p.x >= 0 && p.y >= 0 {
                self.set(p.x as u32, p.y as u32, [c.r(), c.g(), c.b()]);
            }
        }
        Ok(())
    }
}
