//! Geometry shared by the SVG and PNG back ends: ranges, ticks, the plot rectangle, the
//! legend and every series in pixel coordinates (origin top left, y down).
//!
//! Text sizes are those of the PNG bitmap fonts (monospace), which bound the width of the
//! SVG's proportional text too.

use crate::ticks::{axis_ticks, log_ticks_exp, Label};
use crate::{series_color, series_marker, Chart, Marker, Rgb, Series};

/// Character cell (width, height) of each text role, in pixels.
pub(crate) const TITLE_FONT: (f64, f64) = (10.0, 20.0);
pub(crate) const LABEL_FONT: (f64, f64) = (10.0, 20.0);
pub(crate) const TICK_FONT: (f64, f64) = (9.0, 18.0);
pub(crate) const EXP_FONT: (f64, f64) = (7.0, 13.0);
pub(crate) const LEGEND_FONT: (f64, f64) = (9.0, 18.0);
/// How far a superscript's centre sits above the base text's centre.
pub(crate) const EXP_RAISE: f64 = 7.0;

const PAD: f64 = 16.0;
const TICK_LEN: f64 = 6.0;
const LEGEND_ROW: f64 = 26.0;
const LEGEND_SAMPLE: f64 = 36.0;
/// Largest magnitude accepted on a linear axis, so that spans and padding stay finite.
const LINEAR_LIMIT: f64 = 1e300;

/// Whether `v` can be placed on an axis of this kind.
pub(crate) fn showable(v: f64, log: bool) -> bool {
    if log {
        v.is_finite() && v > 0.0
    } else {
        v.is_finite() && v.abs() <= LINEAR_LIMIT
    }
}

#[derive(Debug, Clone, Copy)]
pub(crate) struct Rect {
    pub x0: f64,
    pub y0: f64,
    pub x1: f64,
    pub y1: f64,
}

/// One axis: its range in transformed space (log10 for log axes) and its ticks in pixels.
#[derive(Debug)]
pub(crate) struct Axis {
    log: bool,
    lo: f64,
    hi: f64,
    /// Pixel positions of `lo` and `hi`.
    p0: f64,
    p1: f64,
    pub major: Vec<(f64, Label)>,
    pub minor: Vec<f64>,
}

impl Axis {
    fn new(values: &[f64], log: bool) -> Axis {
        let t: Vec<f64> = values.iter().map(|&v| if log { v.log10() } else { v }).collect();
        let (mut lo, mut hi) = t.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
        if !(lo.is_finite() && hi.is_finite()) {
            // No data: a default range.
            (lo, hi) = (0.0, 1.0);
        }
        let span = hi - lo;
        let tiny = if log { 1e-3 } else { (1e-9 * lo.abs().max(hi.abs())).max(1e-280) };
        if span <= tiny {
            let mid = 0.5 * (lo + hi);
            let half = if log {
                0.5
            } else if mid.abs() < 1e-270 {
                1.0
            } else {
                0.1 * mid.abs()
            };
            (lo, hi) = (mid - half, mid + half);
        } else {
            let pad = 0.05 * span;
            (lo, hi) = (lo - pad, hi + pad);
        }
        let (major, minor) = if log {
            let (major, minor) = log_ticks_exp(lo, hi);
            (major.into_iter().map(|(v, l)| (v.log10(), l)).collect(), minor.into_iter().map(f64::log10).collect())
        } else {
            axis_ticks(lo, hi, false)
        };
        Axis { log, lo, hi, p0: 0.0, p1: 1.0, major, minor }
    }

    /// Fix the pixel span and convert the ticks to pixels.
    fn place(&mut self, p0: f64, p1: f64) {
        self.p0 = p0;
        self.p1 = p1;
        let (lo, hi) = (self.lo, self.hi);
        let to_px = |t: f64| p0 + (t - lo) / (hi - lo) * (p1 - p0);
        for (t, _) in &mut self.major {
            *t = to_px(*t);
        }
        for t in &mut self.minor {
            *t = to_px(*t);
        }
    }

    /// Pixel position of a data value (must be showable).
    fn px(&self, v: f64) -> f64 {
        let t = if self.log { v.log10() } else { v };
        self.p0 + (t - self.lo) / (self.hi - self.lo) * (self.p1 - self.p0)
    }
}

/// One series in pixels.
#[derive(Debug)]
pub(crate) struct SeriesGeom {
    pub color: Rgb,
    pub marker: Marker,
    /// Maximal runs of consecutive showable points, each drawn as one polyline.
    pub runs: Vec<Vec<(f64, f64)>>,
    pub bars: Vec<ErrorBar>,
}

/// A vertical error bar in pixels; an end that runs off the plot gets no cap.
#[derive(Debug)]
pub(crate) struct ErrorBar {
    pub x: f64,
    pub top: f64,
    pub bottom: f64,
    pub cap_top: bool,
    pub cap_bottom: bool,
}

#[derive(Debug)]
pub(crate) struct LegendRow {
    pub name: String,
    pub color: Rgb,
    pub marker: Marker,
    /// Vertical centre of the row.
    pub y: f64,
}

#[derive(Debug)]
pub(crate) struct Legend {
    pub rect: Rect,
    pub sample_x0: f64,
    pub sample_x1: f64,
    pub text_x: f64,
    pub rows: Vec<LegendRow>,
}

/// A text item: content and the position of its centre (or its right end for y tick labels).
#[derive(Debug)]
pub(crate) struct TextItem {
    pub text: String,
    pub x: f64,
    pub y: f64,
}

#[derive(Debug)]
pub(crate) struct Layout {
    pub w: f64,
    pub h: f64,
    pub plot: Rect,
    pub x: Axis,
    pub y: Axis,
    /// Centre of the x tick labels' base text.
    pub x_tick_y: f64,
    /// Right end of the y tick labels.
    pub y_tick_x: f64,
    pub title: Option<TextItem>,
    pub x_label: Option<TextItem>,
    /// Centre of the rotated y label.
    pub y_label: Option<TextItem>,
    pub series: Vec<SeriesGeom>,
    pub legend: Option<Legend>,
    /// Shown in the middle of an empty plot.
    pub message: Option<TextItem>,
}

/// Text on one line: newlines and other control characters become spaces.
pub(crate) fn one_line(s: &str) -> String {
    s.chars().map(|c| if c.is_control() { ' ' } else { c }).collect::<String>().trim().to_string()
}

/// `s` cut to at most `max` characters, ending in "..." when cut.
pub(crate) fn truncate(s: &str, max: usize) -> String {
    if s.chars().count() <= max {
        return s.to_string();
    }
    let keep = max.saturating_sub(3);
    s.chars().take(keep).chain("...".chars()).take(max.max(3)).collect()
}

/// Width in pixels of a tick label.
pub(crate) fn tick_label_width(label: &Label) -> f64 {
    match label {
        Label::Plain(s) => TICK_FONT.0 * s.chars().count() as f64,
        Label::Pow10(k) => 2.0 * TICK_FONT.0 + EXP_FONT.0 * k.to_string().len() as f64,
    }
}

impl Layout {
    pub(crate) fn new(chart: &Chart, w: f64, h: f64) -> Layout {
        let (xs, ys) = showable_values(chart);
        let empty = xs.is_empty();
        let mut x = Axis::new(&xs, chart.log_x);
        let mut y = Axis::new(&ys, chart.log_y);

        let title = one_line(&chart.title);
        let x_label = one_line(&chart.x_label);
        let y_label = one_line(&chart.y_label);
        let (names, legend_w) = legend_names(chart, w);

        let y_tick_w = y.major.iter().map(|(_, l)| tick_label_width(l)).fold(0.0, f64::max);
        let x0 = PAD + if y_label.is_empty() { 0.0 } else { LABEL_FONT.1 + 12.0 } + y_tick_w + TICK_LEN + 6.0;
        let x1 = if legend_w > 0.0 { w - PAD - legend_w - PAD } else { w - PAD - 24.0 };
        let y0 = PAD + if title.is_empty() { 0.0 } else { TITLE_FONT.1 + 14.0 } + 10.0;
        let y1 = h - PAD - if x_label.is_empty() { 0.0 } else { LABEL_FONT.1 + 10.0 } - (TICK_LEN + 4.0 + 24.0);
        let plot = Rect { x0, y0, x1: x1.max(x0 + 10.0), y1: y1.max(y0 + 10.0) };
        x.place(plot.x0, plot.x1);
        y.place(plot.y1, plot.y0);
        let x_tick_y = plot.y1 + TICK_LEN + 4.0 + EXP_RAISE + TICK_FONT.1 / 2.0;
        let y_tick_x = plot.x0 - TICK_LEN - 6.0;

        let series = chart.series.iter().enumerate().map(|(i, s)| series_geom(chart, i, s, &x, &y, plot)).collect();
        let legend = legend(names, legend_w, plot);

        let text = |t: String, x: f64, y: f64| (!t.is_empty()).then_some(TextItem { text: t, x, y });
        Layout {
            w,
            h,
            title: text(title, w / 2.0, PAD + TITLE_FONT.1 / 2.0),
            x_label: text(x_label, (plot.x0 + plot.x1) / 2.0, x_tick_y + TICK_FONT.1 / 2.0 + 8.0 + LABEL_FONT.1 / 2.0),
            y_label: text(y_label, PAD + LABEL_FONT.1 / 2.0, (plot.y0 + plot.y1) / 2.0),
            message: if empty {
                text("no data to plot".into(), (plot.x0 + plot.x1) / 2.0, (plot.y0 + plot.y1) / 2.0)
            } else {
                None
            },
            plot,
            x,
            y,
            x_tick_y,
            y_tick_x,
            series,
            legend,
        }
    }
}

/// The showable x and y values of every point (with the showable ends of its error bar),
/// for the axis ranges.
fn showable_values(chart: &Chart) -> (Vec<f64>, Vec<f64>) {
    let mut xs = Vec::new();
    let mut ys = Vec::new();
    for s in &chart.series {
        for (j, &(x, y)) in s.points.iter().enumerate() {
            if !(showable(x, chart.log_x) && showable(y, chart.log_y)) {
                continue;
            }
            xs.push(x);
            ys.push(y);
            if let Some(&(lo, hi)) = s.band.as_ref().and_then(|b| b.get(j)) {
                ys.extend([lo, hi].into_iter().filter(|&v| showable(v, chart.log_y)));
            }
        }
    }
    (xs, ys)
}

/// The legend's (possibly shortened) names and its width in pixels (0 without series).
fn legend_names(chart: &Chart, w: f64) -> (Vec<String>, f64) {
    let max_chars = (((0.3 * w - 70.0) / LEGEND_FONT.0).floor() as usize).max(6);
    let names: Vec<String> = chart.series.iter().map(|s| truncate(&one_line(&s.name), max_chars)).collect();
    let longest = names.iter().map(|n| n.chars().count()).max().unwrap_or(0);
    let legend_w =
        if names.is_empty() { 0.0 } else { 12.0 + LEGEND_SAMPLE + 10.0 + LEGEND_FONT.0 * longest as f64 + 12.0 };
    (names, legend_w)
}

/// Series `i` in pixels: runs of showable points and error bars.
fn series_geom(chart: &Chart, i: usize, s: &Series, x: &Axis, y: &Axis, plot: Rect) -> SeriesGeom {
    let mut runs = Vec::new();
    let mut run = Vec::new();
    let mut bars = Vec::new();
    for (j, &(px, py)) in s.points.iter().enumerate() {
        if !(showable(px, chart.log_x) && showable(py, chart.log_y)) {
            if !run.is_empty() {
                runs.push(std::mem::take(&mut run));
            }
            continue;
        }
        let (cx, cy) = (x.px(px), y.px(py));
        run.push((cx, cy));
        if let Some(&(lo, hi)) = s.band.as_ref().and_then(|b| b.get(j)) {
            if let Some(bar) = error_bar(cx, lo, hi, y, chart.log_y, plot) {
                bars.push(bar);
            }
        }
    }
    if !run.is_empty() {
        runs.push(run);
    }
    SeriesGeom { color: series_color(i), marker: series_marker(i), runs, bars }
}

/// The error bar from `lo` to `hi` at pixel column `cx`; `None` if an end is NaN. An end
/// that cannot be shown runs to the plot edge on its side, uncapped.
fn error_bar(cx: f64, lo: f64, hi: f64, y: &Axis, log_y: bool, plot: Rect) -> Option<ErrorBar> {
    if lo.is_nan() || hi.is_nan() {
        return None;
    }
    let end = |v: f64| {
        let p = if showable(v, log_y) {
            y.px(v)
        } else if v > 0.0 {
            f64::NEG_INFINITY
        } else {
            f64::INFINITY
        };
        (p.clamp(plot.y0, plot.y1), (plot.y0..=plot.y1).contains(&p))
    };
    let (a, b) = (end(lo), end(hi));
    let (top, bottom) = if a.0 <= b.0 { (a, b) } else { (b, a) };
    Some(ErrorBar { x: cx, top: top.0, bottom: bottom.0, cap_top: top.1, cap_bottom: bottom.1 })
}

/// The legend right of the plot, one row per name (`None` without series).
fn legend(names: Vec<String>, legend_w: f64, plot: Rect) -> Option<Legend> {
    (!names.is_empty()).then(|| {
        let lx0 = plot.x1 + PAD;
        let rows: Vec<LegendRow> = names
            .into_iter()
            .enumerate()
            .map(|(i, name)| LegendRow {
                name,
                color: series_color(i),
                marker: series_marker(i),
                y: plot.y0 + 6.0 + LEGEND_ROW * (i as f64 + 0.5),
            })
            .collect();
        Legend {
            rect: Rect {
                x0: lx0,
                y0: plot.y0,
                x1: lx0 + legend_w,
                y1: plot.y0 + 12.0 + LEGEND_ROW * rows.len() as f64,
            },
            sample_x0: lx0 + 12.0,
            sample_x1: lx0 + 12.0 + LEGEND_SAMPLE,
            text_x: lx0 + 12.0 + LEGEND_SAMPLE + 10.0,
            rows,
        }
    })
}

/// A marker's outline, centred on a point.
#[derive(Debug)]
pub(crate) enum MarkerShape {
    /// A filled disc of this radius.
    Disc(f64),
    /// A filled polygon.
    Polygon(Vec<(f64, f64)>),
    /// Stroked segments of the given width.
    Strokes(Vec<((f64, f64), (f64, f64))>, f64),
}

/// The shape of `marker` centred on `(cx, cy)`, about 11 pixels across.
pub(crate) fn marker_shape(marker: Marker, cx: f64, cy: f64) -> MarkerShape {
    match marker {
        Marker::Circle => MarkerShape::Disc(5.0),
        Marker::Square => MarkerShape::Polygon(vec![
            (cx - 4.5, cy - 4.5),
            (cx + 4.5, cy - 4.5),
            (cx + 4.5, cy + 4.5),
            (cx - 4.5, cy + 4.5),
        ]),
        Marker::TriangleUp => MarkerShape::Polygon(vec![(cx, cy - 6.5), (cx + 6.0, cy + 4.5), (cx - 6.0, cy + 4.5)]),
        Marker::TriangleDown => MarkerShape::Polygon(vec![(cx, cy + 6.5), (cx - 6.0, cy - 4.5), (cx + 6.0, cy - 4.5)]),
        Marker::Diamond => MarkerShape::Polygon(vec![(cx, cy - 6.5), (cx + 5.5, cy), (cx, cy + 6.5), (cx - 5.5, cy)]),
        Marker::Cross => MarkerShape::Strokes(
            vec![((cx - 5.0, cy - 5.0), (cx + 5.0, cy + 5.0)), ((cx - 5.0, cy + 5.0), (cx + 5.0, cy - 5.0))],
            2.5,
        ),
        Marker::Plus => {
            MarkerShape::Strokes(vec![((cx - 6.0, cy), (cx + 6.0, cy)), ((cx, cy - 6.0), (cx, cy + 6.0))], 2.5)
        }
    }
}
