//! PNG back end: shapes drawn with `embedded-graphics` into an RGB framebuffer at twice
//! the size and averaged down (cheap anti-aliasing), then text drawn at full size with
//! the built-in ISO 8859-1 bitmap fonts, then PNG encoding.

use std::convert::Infallible;

use embedded_graphics::mono_font::iso_8859_1::{FONT_10X20, FONT_7X13, FONT_9X18};
use embedded_graphics::mono_font::{MonoFont, MonoTextStyle};
use embedded_graphics::pixelcolor::Rgb888;
use embedded_graphics::prelude::*;
use embedded_graphics::primitives::{Circle, Line, PrimitiveStyle, Rectangle, Triangle};
use embedded_graphics::text::{Alignment, Baseline, Text, TextStyleBuilder};

use crate::layout::{marker_shape, tick_label_width, truncate, Layout, MarkerShape, Rect, EXP_RAISE, TICK_FONT};
use crate::ticks::Label;
use crate::{Marker, PlotError, Rgb};

/// Supersampling factor of the shape pass.
pub(crate) const S: f64 = 2.0;
const WHITE: Rgb888 = Rgb888::new(255, 255, 255);
const BLACK: Rgb888 = Rgb888::new(0, 0, 0);
const GRID_MAJOR: Rgb888 = Rgb888::new(0xcc, 0xcc, 0xcc);
const GRID_MINOR: Rgb888 = Rgb888::new(0xec, 0xec, 0xec);
const LEGEND_BORDER: Rgb888 = Rgb888::new(0x99, 0x99, 0x99);
const GREY_TEXT: Rgb888 = Rgb888::new(0x66, 0x66, 0x66);

fn rgb(c: Rgb) -> Rgb888 {
    Rgb888::new(c.0, c.1, c.2)
}

/// An RGB8 framebuffer; drawing outside it is ignored.
pub(crate) struct Canvas {
    pub(crate) w: u32,
    pub(crate) h: u32,
    pub(crate) px: Vec<u8>,
}

impl Canvas {
    pub(crate) fn new(w: u32, h: u32) -> Canvas {
        Canvas { w, h, px: vec![255; w as usize * h as usize * 3] }
    }

    pub(crate) fn set(&mut self, x: i32, y: i32, c: Rgb888) {
        if x >= 0 && y >= 0 && (x as u32) < self.w && (y as u32) < self.h {
            let i = (y as usize * self.w as usize + x as usize) * 3;
            self.px[i..i + 3].copy_from_slice(&[c.r(), c.g(), c.b()]);
        }
    }

    /// Fill the pixel rectangle `[x0, x1) × [y0, y1)` (clamped to the canvas).
    fn fill(&mut self, x0: i64, y0: i64, x1: i64, y1: i64, c: Rgb888) {
        let (x0, x1) = (x0.clamp(0, i64::from(self.w)), x1.clamp(0, i64::from(self.w)));
        let (y0, y1) = (y0.clamp(0, i64::from(self.h)), y1.clamp(0, i64::from(self.h)));
        for y in y0..y1 {
            for x in x0..x1 {
                self.set(x as i32, y as i32, c);
            }
        }
    }

    /// Average `k`×`k` blocks.
    pub(crate) fn downsample(&self, k: u32) -> Canvas {
        let (w, h) = (self.w / k, self.h / k);
        let mut out = Canvas::new(w, h);
        let n = k * k;
        for y in 0..h {
            for x in 0..w {
                let mut sum = [0u32; 3];
                for dy in 0..k {
                    let row = ((y * k + dy) * self.w) as usize;
                    for dx in 0..k {
                        let i = (row + (x * k + dx) as usize) * 3;
                        for (s, &v) in sum.iter_mut().zip(&self.px[i..i + 3]) {
                            *s += u32::from(v);
                        }
                    }
                }
                let o = ((y * w + x) * 3) as usize;
                for (d, s) in out.px[o..o + 3].iter_mut().zip(sum) {
                    *d = ((s + n / 2) / n) as u8;
                }
            }
        }
        out
    }
}

impl OriginDimensions for Canvas {
    fn size(&self) -> Size {
        Size::new(self.w, self.h)
    }
}

impl DrawTarget for Canvas {
    type Color = Rgb888;
    type Error = Infallible;

    fn draw_iter<I: IntoIterator<Item = Pixel<Rgb888>>>(&mut self, pixels: I) -> Result<(), Infallible> {
        for Pixel(p, c) in pixels {
            self.set(p.x, p.y, c);
        }
        Ok(())
    }
}

/// Draws onto a canvas rotated 90° counter-clockwise about `origin`: text drawn along +x
/// reads bottom to top.
struct Rotated<'a> {
    inner: &'a mut Canvas,
    origin: Point,
}

impl Dimensions for Rotated<'_> {
    fn bounding_box(&self) -> Rectangle {
        Rectangle::new(Point::new(-100_000, -100_000), Size::new(200_000, 200_000))
    }
}

impl DrawTarget for Rotated<'_> {
    type Color = Rgb888;
    type Error = Infallible;

    fn draw_iter<I: IntoIterator<Item = Pixel<Rgb888>>>(&mut self, pixels: I) -> Result<(), Infallible> {
        for Pixel(p, c) in pixels {
            self.inner.set(self.origin.x + p.y, self.origin.y - p.x, c);
        }
        Ok(())
    }
}

/// A layout coordinate on the supersampled canvas.
fn pt(x: f64, y: f64) -> Point {
    // `as` saturates (and maps NaN to 0): never a panic.
    Point::new((x * S).round() as i32, (y * S).round() as i32)
}

/// A crisp one-pixel vertical line at layout x, from y0 to y1.
fn vline(c: &mut Canvas, x: f64, y0: f64, y1: f64, color: Rgb888) {
    let k = S as i64;
    let col = x.floor() as i64;
    c.fill(col * k, y0.floor() as i64 * k, (col + 1) * k, (y1.floor() as i64 + 1) * k, color);
}

/// A crisp one-pixel horizontal line at layout y, from x0 to x1.
fn hline(c: &mut Canvas, y: f64, x0: f64, x1: f64, color: Rgb888) {
    let k = S as i64;
    let row = y.floor() as i64;
    c.fill(x0.floor() as i64 * k, row * k, (x1.floor() as i64 + 1) * k, (row + 1) * k, color);
}

fn frame(c: &mut Canvas, r: Rect, color: Rgb888) {
    hline(c, r.y0, r.x0, r.x1, color);
    hline(c, r.y1, r.x0, r.x1, color);
    vline(c, r.x0, r.y0, r.y1, color);
    vline(c, r.x1, r.y0, r.y1, color);
}

pub(crate) fn stroke<D: DrawTarget<Color = Rgb888>>(
    d: &mut D,
    a: (f64, f64),
    b: (f64, f64),
    width: f64,
    color: Rgb888,
) {
    let w = (width * S).round().max(1.0) as u32;
    let _ = Line::new(pt(a.0, a.1), pt(b.0, b.1)).into_styled(PrimitiveStyle::with_stroke(color, w)).draw(d);
}

pub(crate) fn disc<D: DrawTarget<Color = Rgb888>>(d: &mut D, x: f64, y: f64, radius: f64, color: Rgb888) {
    let diameter = (2.0 * radius * S).round().max(1.0) as u32;
    let _ = Circle::with_center(pt(x, y), diameter).into_styled(PrimitiveStyle::with_fill(color)).draw(d);
}

pub(crate) fn polygon<D: DrawTarget<Color = Rgb888>>(d: &mut D, pts: &[(f64, f64)], color: Rgb888) {
    let style = PrimitiveStyle::with_fill(color);
    for i in 1..pts.len().saturating_sub(1) {
        let (a, b, c) = (pts[0], pts[i], pts[i + 1]);
        let _ = Triangle::new(pt(a.0, a.1), pt(b.0, b.1), pt(c.0, c.1)).into_styled(style).draw(d);
    }
}

/// A polyline with round joins.
pub(crate) fn polyline<D: DrawTarget<Color = Rgb888>>(d: &mut D, run: &[(f64, f64)], width: f64, color: Rgb888) {
    for seg in run.windows(2) {
        stroke(d, seg[0], seg[1], width, color);
    }
    if run.len() >= 2 {
        for &(x, y) in run {
            disc(d, x, y, width / 2.0, color);
        }
    }
}

/// A marker with a thin white outline, like the SVG's.
fn marker<D: DrawTarget<Color = Rgb888>>(d: &mut D, m: Marker, cx: f64, cy: f64, color: Rgb888) {
    match marker_shape(m, cx, cy) {
        MarkerShape::Disc(r) => {
            disc(d, cx, cy, r + 1.0, WHITE);
            disc(d, cx, cy, r, color);
        }
        MarkerShape::Polygon(pts) => {
            let grown: Vec<(f64, f64)> = pts
                .iter()
                .map(|&(x, y)| {
                    let (dx, dy) = (x - cx, y - cy);
                    let len = dx.hypot(dy).max(1e-9);
                    (x + 1.4 * dx / len, y + 1.4 * dy / len)
                })
                .collect();
            polygon(d, &grown, WHITE);
            polygon(d, &pts, color);
        }
        MarkerShape::Strokes(segs, w) => {
            for &(a, b) in &segs {
                stroke(d, a, b, w + 2.0, WHITE);
            }
            for &(a, b) in &segs {
                stroke(d, a, b, w, color);
            }
        }
    }
}

pub(crate) fn text<D: DrawTarget<Color = Rgb888>>(
    d: &mut D,
    s: &str,
    font: &MonoFont<'_>,
    x: f64,
    y: f64,
    align: Alignment,
    color: Rgb888,
) {
    let style = MonoTextStyle::new(font, color);
    let ts = TextStyleBuilder::new().alignment(align).baseline(Baseline::Middle).build();
    let p = Point::new(x.round() as i32, y.round() as i32);
    let _ = Text::with_text_style(s, p, style, ts).draw(d);
}

/// A tick label whose left end is at `left` and whose base text is centred on `y`.
fn tick_label(c: &mut Canvas, label: &Label, left: f64, y: f64) {
    match label {
        Label::Plain(s) => text(c, s, &FONT_9X18, left, y, Alignment::Left, BLACK),
        Label::Pow10(k) => {
            text(c, "10", &FONT_9X18, left, y, Alignment::Left, BLACK);
            text(c, &k.to_string(), &FONT_7X13, left + 2.0 * TICK_FONT.0, y - EXP_RAISE, Alignment::Left, BLACK);
        }
    }
}

/// Draw the layout into an RGB8 buffer of `width`×`height`.
pub(crate) fn render(l: &Layout, width: u32, height: u32) -> Vec<u8> {
    let k = S as u32;
    let mut big = Canvas::new(width * k, height * k);
    let p = l.plot;

    // Grid, tick marks, frame.
    for &x in &l.x.minor {
        vline(&mut big, x, p.y0, p.y1, GRID_MINOR);
    }
    for &y in &l.y.minor {
        hline(&mut big, y, p.x0, p.x1, GRID_MINOR);
    }
    for (x, _) in &l.x.major {
        vline(&mut big, *x, p.y0, p.y1, GRID_MAJOR);
        vline(&mut big, *x, p.y1, p.y1 + 6.0, BLACK);
    }
    for (y, _) in &l.y.major {
        hline(&mut big, *y, p.x0, p.x1, GRID_MAJOR);
        hline(&mut big, *y, p.x0 - 6.0, p.x0, BLACK);
    }
    frame(&mut big, p, BLACK);

    // Series, clipped to the plot area.
    {
        let clip = Rectangle::with_corners(pt(p.x0, p.y0), pt(p.x1 + 1.0, p.y1 + 1.0));
        let mut d = big.clipped(&clip);
        for s in &l.series {
            let c = rgb(s.color);
            for b in &s.bars {
                stroke(&mut d, (b.x, b.top), (b.x, b.bottom), 1.5, c);
                for (y, cap) in [(b.top, b.cap_top), (b.bottom, b.cap_bottom)] {
                    if cap {
                        stroke(&mut d, (b.x - 4.0, y), (b.x + 4.0, y), 1.5, c);
                    }
                }
            }
            for run in &s.runs {
                polyline(&mut d, run, 2.0, c);
            }
            for &(x, y) in s.runs.iter().flatten() {
                marker(&mut d, s.marker, x, y, c);
            }
        }
    }

    // Legend box and samples.
    if let Some(g) = &l.legend {
        let r = g.rect;
        big.fill((r.x0 * S) as i64, (r.y0 * S) as i64, (r.x1 * S) as i64, (r.y1 * S) as i64, WHITE);
        frame(&mut big, r, LEGEND_BORDER);
        for row in &g.rows {
            let c = rgb(row.color);
            stroke(&mut big, (g.sample_x0, row.y), (g.sample_x1, row.y), 2.0, c);
            marker(&mut big, row.marker, (g.sample_x0 + g.sample_x1) / 2.0, row.y, c);
        }
    }

    // Text at full resolution.
    let mut c = big.downsample(k);
    for (x, label) in &l.x.major {
        tick_label(&mut c, label, x - tick_label_width(label) / 2.0, l.x_tick_y);
    }
    for (y, label) in &l.y.major {
        tick_label(&mut c, label, l.y_tick_x - tick_label_width(label), *y);
    }
    if let Some(t) = &l.title {
        let max = ((l.w - 32.0) / 10.0).max(3.0) as usize;
        text(&mut c, &truncate(&t.text, max), &FONT_10X20, t.x, t.y, Alignment::Center, BLACK);
    }
    if let Some(t) = &l.x_label {
        let max = ((p.x1 - p.x0) / 10.0).max(3.0) as usize;
        text(&mut c, &truncate(&t.text, max), &FONT_10X20, t.x, t.y, Alignment::Center, BLACK);
    }
    if let Some(t) = &l.y_label {
        let max = ((p.y1 - p.y0) / 10.0).max(3.0) as usize;
        let origin = Point::new(t.x.round() as i32, t.y.round() as i32);
        let mut r = Rotated { inner: &mut c, origin };
        text(&mut r, &truncate(&t.text, max), &FONT_10X20, 0.0, 0.0, Alignment::Center, BLACK);
    }
    if let Some(t) = &l.message {
        text(&mut c, &t.text, &FONT_10X20, t.x, t.y, Alignment::Center, GREY_TEXT);
    }
    if let Some(g) = &l.legend {
        for row in &g.rows {
            text(&mut c, &row.name, &FONT_9X18, g.text_x, row.y, Alignment::Left, BLACK);
        }
    }
    c.px
}

/// Encode an RGB8 buffer as PNG.
pub(crate) fn encode_png(rgb: &[u8], width: u32, height: u32) -> Result<Vec<u8>, PlotError> {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, width, height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let err = |e: png::EncodingError| PlotError::Png(e.to_string());
    let mut w = enc.write_header().map_err(err)?;
    w.write_image_data(rgb).map_err(err)?;
    w.finish().map_err(err)?;
    Ok(out)
}
