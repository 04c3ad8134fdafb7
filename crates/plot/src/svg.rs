//! SVG back end: plain SVG 1.1 with text as `<text>` elements.

use std::fmt::Write;

use crate::layout::{marker_shape, Layout, Legend, MarkerShape, EXP_RAISE};
use crate::ticks::Label;
use crate::Rgb;

const FONT_FAMILY: &str = "DejaVu Sans, Helvetica, Arial, sans-serif";
const TITLE_SIZE: f64 = 20.0;
const LABEL_SIZE: f64 = 17.0;
const TICK_SIZE: f64 = 15.0;
const EXP_SIZE: f64 = 11.0;
const LEGEND_SIZE: f64 = 15.0;
const GRID_MAJOR: &str = "#cccccc";
const GRID_MINOR: &str = "#ececec";

/// Escape text for XML content and attribute values, dropping characters XML 1.0 forbids.
pub(crate) fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\t' | '\n' | '\r' => out.push(' '),
            c if (c as u32) < 0x20 || c == '\u{FFFE}' || c == '\u{FFFF}' => {}
            c => out.push(c),
        }
    }
    out
}

/// A coordinate with two decimals, trailing zeros dropped.
pub(crate) fn n(v: f64) -> String {
    let s = format!("{v:.2}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

/// `size`, shrunk when a rough width estimate of `text` (sans-serif, ~0.55 em a character,
/// ~0.6 em bold) exceeds `avail` pixels, so long labels stay inside the picture.
fn fit(text: &str, size: f64, bold: bool, avail: f64) -> f64 {
    let em = if bold { 0.6 } else { 0.55 };
    let estimate = em * size * text.chars().count() as f64;
    if estimate > avail && avail > 0.0 {
        (size * avail / estimate).max(6.0)
    } else {
        size
    }
}

/// Baseline for text whose visual centre should sit at `y`.
fn baseline(y: f64, size: f64) -> f64 {
    y + 0.35 * size
}

fn tick_label(out: &mut String, label: &Label, x: f64, y: f64, anchor: &str) {
    let _ = write!(
        out,
        r#"<text x="{}" y="{}" font-size="{TICK_SIZE}" text-anchor="{anchor}">"#,
        n(x),
        n(baseline(y, TICK_SIZE))
    );
    match label {
        Label::Plain(s) => out.push_str(&escape(s)),
        Label::Pow10(k) => {
            let _ = write!(out, r#"10<tspan dy="{}" font-size="{EXP_SIZE}">{k}</tspan>"#, n(-EXP_RAISE));
        }
    }
    out.push_str("</text>\n");
}

fn marker(out: &mut String, m: crate::Marker, cx: f64, cy: f64, color: Rgb) {
    let c = color.hex();
    match marker_shape(m, cx, cy) {
        MarkerShape::Disc(r) => {
            let _ = writeln!(
                out,
                r#"<circle cx="{}" cy="{}" r="{}" fill="{c}" stroke="white" stroke-width="1"/>"#,
                n(cx),
                n(cy),
                n(r)
            );
        }
        MarkerShape::Polygon(pts) => {
            let pts: Vec<String> = pts.iter().map(|&(x, y)| format!("{},{}", n(x), n(y))).collect();
            let _ =
                writeln!(out, r#"<polygon points="{}" fill="{c}" stroke="white" stroke-width="1"/>"#, pts.join(" "));
        }
        MarkerShape::Strokes(segs, w) => {
            let mut d = String::new();
            for ((x0, y0), (x1, y1)) in segs {
                let _ = write!(d, "M{},{}L{},{}", n(x0), n(y0), n(x1), n(y1));
            }
            let _ = writeln!(out, r#"<path d="{d}" fill="none" stroke="{c}" stroke-width="{w}"/>"#);
        }
    }
}

pub(crate) fn render(l: &Layout) -> String {
    let mut o = String::new();
    header(&mut o, l);
    grid(&mut o, l);
    ticks_and_frame(&mut o, l);
    tick_labels(&mut o, l);
    series(&mut o, l);
    labels(&mut o, l);
    if let Some(g) = &l.legend {
        legend(&mut o, g);
    }
    o.push_str("</svg>\n");
    o
}

/// XML declaration, the `<svg>` element, the title, the white background and the plot
/// area's clip path.
fn header(o: &mut String, l: &Layout) {
    let p = l.plot;
    let _ = writeln!(o, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        o,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="{FONT_FAMILY}">"#,
        w = n(l.w),
        h = n(l.h)
    );
    if let Some(t) = &l.title {
        let _ = writeln!(o, "<title>{}</title>", escape(&t.text));
    }
    let _ = writeln!(o, r#"<rect x="0" y="0" width="{}" height="{}" fill="white"/>"#, n(l.w), n(l.h));
    let _ = writeln!(
        o,
        r#"<defs><clipPath id="plot-area"><rect x="{}" y="{}" width="{}" height="{}"/></clipPath></defs>"#,
        n(p.x0),
        n(p.y0),
        n(p.x1 - p.x0),
        n(p.y1 - p.y0)
    );
}

/// Grid lines, minor first, then major; opens the crisp-edged group that
/// [`ticks_and_frame`] closes.
fn grid(o: &mut String, l: &Layout) {
    let p = l.plot;
    o.push_str(r#"<g shape-rendering="crispEdges" stroke-width="1">"#);
    o.push('\n');
    for &x in &l.x.minor {
        let _ = writeln!(
            o,
            r#"<line x1="{x}" y1="{}" x2="{x}" y2="{}" stroke="{GRID_MINOR}"/>"#,
            n(p.y0),
            n(p.y1),
            x = n(x)
        );
    }
    for &y in &l.y.minor {
        let _ = writeln!(
            o,
            r#"<line x1="{}" y1="{y}" x2="{}" y2="{y}" stroke="{GRID_MINOR}"/>"#,
            n(p.x0),
            n(p.x1),
            y = n(y)
        );
    }
    for (x, _) in &l.x.major {
        let _ = writeln!(
            o,
            r#"<line x1="{x}" y1="{}" x2="{x}" y2="{}" stroke="{GRID_MAJOR}"/>"#,
            n(p.y0),
            n(p.y1),
            x = n(*x)
        );
    }
    for (y, _) in &l.y.major {
        let _ = writeln!(
            o,
            r#"<line x1="{}" y1="{y}" x2="{}" y2="{y}" stroke="{GRID_MAJOR}"/>"#,
            n(p.x0),
            n(p.x1),
            y = n(*y)
        );
    }
}

/// Tick marks and the frame; closes the group [`grid`] opened.
fn ticks_and_frame(o: &mut String, l: &Layout) {
    let p = l.plot;
    for (x, _) in &l.x.major {
        let _ = writeln!(
            o,
            r#"<line x1="{x}" y1="{}" x2="{x}" y2="{}" stroke="black"/>"#,
            n(p.y1),
            n(p.y1 + 6.0),
            x = n(*x)
        );
    }
    for (y, _) in &l.y.major {
        let _ = writeln!(
            o,
            r#"<line x1="{}" y1="{y}" x2="{}" y2="{y}" stroke="black"/>"#,
            n(p.x0 - 6.0),
            n(p.x0),
            y = n(*y)
        );
    }
    let _ = writeln!(
        o,
        r#"<rect x="{}" y="{}" width="{}" height="{}" fill="none" stroke="black"/>"#,
        n(p.x0),
        n(p.y0),
        n(p.x1 - p.x0),
        n(p.y1 - p.y0)
    );
    o.push_str("</g>\n");
}

/// The tick labels of both axes.
fn tick_labels(o: &mut String, l: &Layout) {
    o.push_str("<g fill=\"black\">\n");
    for (x, label) in &l.x.major {
        tick_label(o, label, *x, l.x_tick_y, "middle");
    }
    for (y, label) in &l.y.major {
        tick_label(o, label, l.y_tick_x, *y, "end");
    }
    o.push_str("</g>\n");
}

/// Every series (error bars, lines, markers), clipped to the plot area.
fn series(o: &mut String, l: &Layout) {
    o.push_str(r#"<g clip-path="url(#plot-area)" stroke-linejoin="round" stroke-linecap="round">"#);
    o.push('\n');
    for s in &l.series {
        let c = s.color.hex();
        for b in &s.bars {
            let mut d = format!("M{x},{t}L{x},{b}", x = n(b.x), t = n(b.top), b = n(b.bottom));
            for (y, cap) in [(b.top, b.cap_top), (b.bottom, b.cap_bottom)] {
                if cap {
                    let _ = write!(d, "M{},{y}L{},{y}", n(b.x - 4.0), n(b.x + 4.0), y = n(y));
                }
            }
            let _ = writeln!(o, r#"<path d="{d}" fill="none" stroke="{c}" stroke-width="1.5"/>"#);
        }
        for run in s.runs.iter().filter(|r| r.len() >= 2) {
            let pts: Vec<String> = run.iter().map(|&(x, y)| format!("{},{}", n(x), n(y))).collect();
            let _ = writeln!(o, r#"<polyline points="{}" fill="none" stroke="{c}" stroke-width="2"/>"#, pts.join(" "));
        }
        for &(x, y) in s.runs.iter().flatten() {
            marker(o, s.marker, x, y, s.color);
        }
    }
    o.push_str("</g>\n");
}

/// Title, axis labels (shrunk to fit) and the empty-plot message.
fn labels(o: &mut String, l: &Layout) {
    let p = l.plot;
    if let Some(t) = &l.title {
        let size = fit(&t.text, TITLE_SIZE, true, l.w - 32.0);
        let _ = writeln!(
            o,
            r#"<text x="{}" y="{}" font-size="{}" font-weight="bold" text-anchor="middle">{}</text>"#,
            n(t.x),
            n(baseline(t.y, size)),
            n(size),
            escape(&t.text)
        );
    }
    if let Some(t) = &l.x_label {
        let size = fit(&t.text, LABEL_SIZE, false, p.x1 - p.x0);
        let _ = writeln!(
            o,
            r#"<text x="{}" y="{}" font-size="{}" text-anchor="middle">{}</text>"#,
            n(t.x),
            n(baseline(t.y, size)),
            n(size),
            escape(&t.text)
        );
    }
    if let Some(t) = &l.y_label {
        let size = fit(&t.text, LABEL_SIZE, false, p.y1 - p.y0);
        let _ = writeln!(
            o,
            r#"<text transform="translate({},{}) rotate(-90)" x="0" y="{}" font-size="{}" text-anchor="middle">{}</text>"#,
            n(t.x),
            n(t.y),
            n(baseline(0.0, size)),
            n(size),
            escape(&t.text)
        );
    }
    if let Some(t) = &l.message {
        let _ = writeln!(
            o,
            r##"<text x="{}" y="{}" font-size="{LABEL_SIZE}" fill="#666666" text-anchor="middle">{}</text>"##,
            n(t.x),
            n(baseline(t.y, LABEL_SIZE)),
            escape(&t.text)
        );
    }
}

/// The legend box: a line sample with the marker and the name per series.
fn legend(o: &mut String, g: &Legend) {
    let r = g.rect;
    let _ = writeln!(
        o,
        r##"<rect x="{}" y="{}" width="{}" height="{}" fill="white" stroke="#999999" stroke-width="1"/>"##,
        n(r.x0),
        n(r.y0),
        n(r.x1 - r.x0),
        n(r.y1 - r.y0)
    );
    for row in &g.rows {
        let _ = writeln!(
            o,
            r#"<line x1="{}" y1="{y}" x2="{}" y2="{y}" stroke="{}" stroke-width="2"/>"#,
            n(g.sample_x0),
            n(g.sample_x1),
            row.color.hex(),
            y = n(row.y)
        );
        marker(o, row.marker, (g.sample_x0 + g.sample_x1) / 2.0, row.y, row.color);
        let _ = writeln!(
            o,
            r#"<text x="{}" y="{}" font-size="{LEGEND_SIZE}">{}</text>"#,
            n(g.text_x),
            n(baseline(row.y, LEGEND_SIZE)),
            escape(&row.name)
        );
    }
}
