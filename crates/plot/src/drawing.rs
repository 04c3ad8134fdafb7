//! Free-form pictures (scatter plots, planar Voronoi diagrams, image grids) written as SVG
//! and PNG from one list of shapes, with the same back ends as [`crate::Chart`]: the SVG
//! by hand, the PNG with `embedded-graphics` at twice the size and averaged down.
//!
//! Coordinates are pixels, x to the right and y down, on a `width` × `height` picture.
//! Non-finite coordinates are skipped, never a panic.

use std::path::Path;

use embedded_graphics::mono_font::iso_8859_1::{FONT_10X20, FONT_6X10, FONT_7X13, FONT_9X18};
use embedded_graphics::pixelcolor::Rgb888;
use embedded_graphics::text::Alignment;

use crate::raster::{self, Canvas, S};
use crate::svg::{escape, n};
use crate::{PlotError, Rgb};

/// Text sizes (the PNG uses the matching bitmap font).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TextSize {
    /// About 10 px.
    Small,
    /// About 13 px.
    Normal,
    /// About 18 px.
    Large,
    /// About 20 px, bold in SVG.
    Title,
}

impl TextSize {
    fn px(self) -> f64 {
        match self {
            TextSize::Small => 10.0,
            TextSize::Normal => 13.0,
            TextSize::Large => 17.0,
            TextSize::Title => 20.0,
        }
    }
}

/// One shape of a [`Drawing`].
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// A filled convex polygon (non-convex ones are drawn as a fan from the first point in
    /// the PNG).
    Polygon {
        /// Vertices, in drawing units.
        points: Vec<(f64, f64)>,
        /// Fill colour.
        fill: Rgb,
    },
    /// An open polyline (repeat the first point to close it).
    Polyline {
        /// Vertices, in drawing units.
        points: Vec<(f64, f64)>,
        /// Line width, in drawing units.
        width: f64,
        /// Colour.
        color: Rgb,
    },
    /// A filled disc.
    Disc {
        /// Centre, in drawing units.
        center: (f64, f64),
        /// Radius, in drawing units.
        radius: f64,
        /// Fill colour.
        fill: Rgb,
    },
    /// Text centred vertically on `pos`, anchored at its left end, centre or right end.
    Text {
        /// Anchor position, in drawing units.
        pos: (f64, f64),
        /// The text.
        text: String,
        /// Font size.
        size: TextSize,
        /// Which point of the text sits at `pos`.
        anchor: Anchor,
        /// Colour.
        color: Rgb,
    },
    /// A grey-scale image of `cols` × `rows` values (0 = black, 255 = white, row-major,
    /// top row first) drawn into the rectangle at `origin` of size `size`, nearest-pixel.
    Gray {
        /// Top-left corner, in drawing units.
        origin: (f64, f64),
        /// Width and height, in drawing units.
        size: (f64, f64),
        /// Values per row.
        cols: usize,
        /// Rows.
        rows: usize,
        /// Grey levels, row-major, top row first.
        values: Vec<u8>,
    },
}

/// Horizontal anchoring of [`Shape::Text`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Anchor {
    /// `pos` is the left end.
    Start,
    /// `pos` is the centre.
    Middle,
    /// `pos` is the right end.
    End,
}

/// A picture: a white background and shapes drawn in order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Drawing {
    /// Width in pixels (SVG user units).
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Drawn in this order.
    pub shapes: Vec<Shape>,
}

fn finite(p: (f64, f64)) -> bool {
    p.0.is_finite() && p.1.is_finite()
}

impl Drawing {
    /// An empty white picture.
    pub fn new(width: u32, height: u32) -> Self {
        Drawing { width, height, shapes: Vec::new() }
    }

    /// Adds a shape.
    pub fn push(&mut self, shape: Shape) -> &mut Self {
        self.shapes.push(shape);
        self
    }

    fn check_size(&self) -> Result<(), PlotError> {
        if !(16..=crate::MAX_SIZE.0).contains(&self.width) || !(16..=crate::MAX_SIZE.1).contains(&self.height) {
            return Err(PlotError::Size { width: self.width, height: self.height });
        }
        Ok(())
    }

    /// The SVG document.
    pub fn to_svg(&self) -> String {
        let mut o = String::new();
        o.push_str(&format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" font-family=\"sans-serif\">\n<rect width=\"{w}\" height=\"{h}\" fill=\"#ffffff\"/>\n",
            w = self.width,
            h = self.height
        ));
        for shape in &self.shapes {
            match shape {
                Shape::Polygon { points, fill } => {
                    let pts: Vec<String> =
                        points.iter().filter(|p| finite(**p)).map(|p| format!("{},{}", n(p.0), n(p.1))).collect();
                    if pts.len() >= 3 {
                        o.push_str(&format!("<polygon points=\"{}\" fill=\"{}\"/>\n", pts.join(" "), fill.hex()));
                    }
                }
                Shape::Polyline { points, width, color } => {
                    for run in points.split(|p| !finite(*p)) {
                        if run.len() >= 2 {
                            let pts: Vec<String> = run.iter().map(|p| format!("{},{}", n(p.0), n(p.1))).collect();
                            o.push_str(&format!(
                                "<polyline points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{}\" stroke-linejoin=\"round\" stroke-linecap=\"round\"/>\n",
                                pts.join(" "),
                                color.hex(),
                                n(*width)
                            ));
                        }
                    }
                }
                Shape::Disc { center, radius, fill } => {
                    if finite(*center) && radius.is_finite() {
                        o.push_str(&format!(
                            "<circle cx=\"{}\" cy=\"{}\" r=\"{}\" fill=\"{}\"/>\n",
                            n(center.0),
                            n(center.1),
                            n(*radius),
                            fill.hex()
                        ));
                    }
                }
                Shape::Text { pos, text, size, anchor, color } => {
                    if finite(*pos) {
                        let a = match anchor {
                            Anchor::Start => "start",
                            Anchor::Middle => "middle",
                            Anchor::End => "end",
                        };
                        let weight = if *size == TextSize::Title { " font-weight=\"bold\"" } else { "" };
                        o.push_str(&format!(
                            "<text x=\"{}\" y=\"{}\" font-size=\"{}\" text-anchor=\"{a}\" dominant-baseline=\"central\" fill=\"{}\"{weight}>{}</text>\n",
                            n(pos.0),
                            n(pos.1),
                            n(size.px()),
                            color.hex(),
                            escape(text)
                        ));
                    }
                }
                Shape::Gray { origin, size, cols, rows, values } => {
                    if !finite(*origin) || !finite(*size) || values.len() != cols * rows || *cols == 0 || *rows == 0 {
                        continue;
                    }
                    let (cw, ch) = (size.0 / *cols as f64, size.1 / *rows as f64);
                    // Runs of equal value along a row become one rectangle.
                    for r in 0..*rows {
                        let row = &values[r * cols..(r + 1) * cols];
                        let mut c = 0;
                        while c < *cols {
                            let v = row[c];
                            let mut e = c + 1;
                            while e < *cols && row[e] == v {
                                e += 1;
                            }
                            o.push_str(&format!(
                                "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"{}\"/>\n",
                                n(origin.0 + c as f64 * cw),
                                n(origin.1 + r as f64 * ch),
                                n((e - c) as f64 * cw + 0.02),
                                n(ch + 0.02),
                                Rgb(v, v, v).hex()
                            ));
                            c = e;
                        }
                    }
                }
            }
        }
        o.push_str("</svg>\n");
        o
    }

    /// The PNG file's bytes.
    ///
    /// # Errors
    /// [`PlotError::Size`] for a picture smaller than 16 px or larger than 4000 px a side,
    /// [`PlotError::Png`] if encoding fails.
    pub fn to_png(&self) -> Result<Vec<u8>, PlotError> {
        self.check_size()?;
        let k = S as u32;
        let mut big = Canvas::new(self.width * k, self.height * k);
        let rgb = |c: Rgb| Rgb888::new(c.0, c.1, c.2);
        let mut texts = Vec::new();
        for shape in &self.shapes {
            match shape {
                Shape::Polygon { points, fill } => {
                    let pts: Vec<(f64, f64)> = points.iter().copied().filter(|p| finite(*p)).collect();
                    raster::polygon(&mut big, &pts, rgb(*fill));
                }
                Shape::Polyline { points, width, color } => {
                    for run in points.split(|p| !finite(*p)) {
                        raster::polyline(&mut big, run, *width, rgb(*color));
                    }
                }
                Shape::Disc { center, radius, fill } => {
                    if finite(*center) && radius.is_finite() {
                        raster::disc(&mut big, center.0, center.1, *radius, rgb(*fill));
                    }
                }
                Shape::Text { .. } => texts.push(shape),
                Shape::Gray { origin, size, cols, rows, values } => {
                    if !finite(*origin) || !finite(*size) || values.len() != cols * rows || *cols == 0 || *rows == 0 {
                        continue;
                    }
                    let x0 = (origin.0 * S).round() as i64;
                    let y0 = (origin.1 * S).round() as i64;
                    let x1 = ((origin.0 + size.0) * S).round() as i64;
                    let y1 = ((origin.1 + size.1) * S).round() as i64;
                    for y in y0.max(0)..y1.min(i64::from(big.h)) {
                        let r = (((y - y0) as f64 + 0.5) / (y1 - y0).max(1) as f64 * *rows as f64) as usize;
                        for x in x0.max(0)..x1.min(i64::from(big.w)) {
                            let c = (((x - x0) as f64 + 0.5) / (x1 - x0).max(1) as f64 * *cols as f64) as usize;
                            let v = values[r.min(rows - 1) * cols + c.min(cols - 1)];
                            big.set(x as i32, y as i32, Rgb888::new(v, v, v));
                        }
                    }
                }
            }
        }
        let mut small = big.downsample(k);
        for shape in texts {
            if let Shape::Text { pos, text, size, anchor, color } = shape {
                if !finite(*pos) {
                    continue;
                }
                let font = match size {
                    TextSize::Small => &FONT_6X10,
                    TextSize::Normal => &FONT_7X13,
                    TextSize::Large => &FONT_9X18,
                    TextSize::Title => &FONT_10X20,
                };
                let align = match anchor {
                    Anchor::Start => Alignment::Left,
                    Anchor::Middle => Alignment::Center,
                    Anchor::End => Alignment::Right,
                };
                raster::text(&mut small, text, font, pos.0, pos.1, align, rgb(*color));
            }
        }
        raster::encode_png(&small.px, self.width, self.height)
    }

    /// Writes [`Drawing::to_svg`] to `path` atomically.
    ///
    /// # Errors
    /// [`PlotError::Size`] (checked before the file is touched) or [`PlotError::Write`].
    pub fn write_svg(&self, path: &Path) -> Result<(), PlotError> {
        self.check_size()?;
        crate::write_atomic(path, self.to_svg().as_bytes())
    }

    /// Writes [`Drawing::to_png`] to `path` atomically.
    ///
    /// # Errors
    /// As [`Drawing::to_png`] (checked before the file is touched), or [`PlotError::Write`].
    pub fn write_png(&self, path: &Path) -> Result<(), PlotError> {
        crate::write_atomic(path, &self.to_png()?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shapes_land_where_asked_in_both_formats() {
        let mut d = Drawing::new(100, 60);
        d.push(Shape::Polygon {
            points: vec![(0.0, 0.0), (50.0, 0.0), (50.0, 60.0), (0.0, 60.0)],
            fill: Rgb(255, 0, 0),
        });
        d.push(Shape::Gray {
            origin: (60.0, 10.0),
            size: (20.0, 20.0),
            cols: 2,
            rows: 2,
            values: vec![0, 255, 255, 0],
        });
        d.push(Shape::Polyline {
            points: vec![(0.0, 0.0), (f64::NAN, 1.0), (1.0, 1.0)],
            width: 1.0,
            color: Rgb(0, 0, 0),
        });
        let svg = d.to_svg();
        assert!(svg.contains("<polygon points=\"0,0 50,0 50,60 0,60\" fill=\"#ff0000\"/>"));
        assert_eq!(svg.matches("<rect").count(), 1 + 4);
        let png = d.to_png().unwrap();
        let decoder = png::Decoder::new(std::io::Cursor::new(png));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        reader.next_frame(&mut buf).unwrap();
        let px = |x: usize, y: usize| &buf[(y * 100 + x) * 3..(y * 100 + x) * 3 + 3];
        assert_eq!(px(25, 30), &[255, 0, 0]);
        assert_eq!(px(75, 30), &[255, 255, 255]);
        assert_eq!(px(64, 14), &[0, 0, 0]);
        assert_eq!(px(75, 14), &[255, 255, 255]);
        assert!(Drawing::new(8, 8).to_png().is_err());
    }
}
