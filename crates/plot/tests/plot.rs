//! Output checks: well-formed SVG with the expected text, decodable PNG of the right size
//! with every series' colour, tick placement, and errors (not panics) for bad input.

use std::io::Cursor;
use std::path::Path;

use plot::{linear_ticks, log_ticks, series_color, Chart, PlotError, Series};
use quick_xml::events::Event;
use quick_xml::Reader;

fn decades(c: f64, p: f64) -> Vec<(f64, f64)> {
    [24.0f64, 96.0, 384.0, 1536.0, 6144.0].iter().map(|&n| (n, c * n.powf(-p))).collect()
}

/// A log-log chart with `n` series, the first with error bars.
fn study(n: usize) -> Chart {
    let series = (0..n)
        .map(|i| {
            let points = decades(0.5 + 0.3 * i as f64, 0.3 + 0.05 * i as f64);
            let band = (i == 0).then(|| points.iter().map(|&(_, y)| (0.8 * y, 1.2 * y)).collect());
            Series { name: format!("Method {i} & <variant> \"{i}\""), points, band }
        })
        .collect();
    Chart {
        title: "Sphere of radius 0.35: Hausdorff distance vs parameters".into(),
        x_label: "parameters".into(),
        y_label: "Hausdorff distance (unit cube)".into(),
        log_x: true,
        log_y: true,
        series,
    }
}

/// Parse `svg` strictly; return the text content of each `<text>` element (unescaped) and
/// the element names seen.
fn parse_svg(svg: &str) -> (Vec<String>, Vec<String>) {
    let mut reader = Reader::from_str(svg);
    reader.config_mut().check_end_names = true;
    let mut stack: Vec<String> = Vec::new();
    let mut names = Vec::new();
    let mut texts = Vec::new();
    let mut roots = 0;
    loop {
        match reader.read_event().expect("SVG is well-formed XML") {
            Event::Start(e) => {
                let name = String::from_utf8(e.name().as_ref().to_vec()).unwrap();
                if stack.is_empty() {
                    roots += 1;
                }
                if name == "text" {
                    texts.push(String::new());
                }
                names.push(name.clone());
                stack.push(name);
            }
            Event::Empty(e) => {
                assert!(!stack.is_empty(), "element outside the root");
                names.push(String::from_utf8(e.name().as_ref().to_vec()).unwrap());
            }
            Event::End(e) => {
                let name = String::from_utf8(e.name().as_ref().to_vec()).unwrap();
                assert_eq!(stack.pop().as_deref(), Some(name.as_str()), "balanced tags");
            }
            Event::Text(t) => {
                let s = t.unescape().expect("valid entities").into_owned();
                if stack.iter().any(|n| n == "text") {
                    texts.last_mut().unwrap().push_str(&s);
                } else if stack.last().map(String::as_str) != Some("title") {
                    assert!(s.trim().is_empty(), "stray text {s:?}");
                }
            }
            Event::Eof => break,
            _ => {}
        }
    }
    assert!(stack.is_empty(), "unclosed elements {stack:?}");
    assert_eq!(roots, 1, "exactly one root element");
    (texts, names)
}

fn decode_png(bytes: &[u8]) -> (u32, u32, Vec<u8>) {
    let decoder = png::Decoder::new(Cursor::new(bytes));
    let mut reader = decoder.read_info().expect("PNG header");
    let mut buf = vec![0; reader.output_buffer_size().expect("size")];
    let info = reader.next_frame(&mut buf).expect("PNG data");
    assert_eq!(info.color_type, png::ColorType::Rgb);
    assert_eq!(info.bit_depth, png::BitDepth::Eight);
    buf.truncate(info.buffer_size());
    (info.width, info.height, buf)
}

fn count_colour(rgb: &[u8], c: plot::Rgb) -> usize {
    rgb.chunks_exact(3).filter(|p| p == &[c.0, c.1, c.2]).count()
}

#[test]
fn svg_is_well_formed_with_names_and_labels() {
    let chart = study(8);
    let svg = chart.to_svg();
    let (texts, names) = parse_svg(&svg);
    assert!(names.iter().any(|n| n == "svg"));
    for s in &chart.series {
        assert!(texts.contains(&s.name), "legend entry {:?} missing from {texts:?}", s.name);
        assert!(svg.contains(&series_color(chart.series.iter().position(|t| t == s).unwrap()).hex()));
    }
    for label in [&chart.title, &chart.x_label, &chart.y_label] {
        assert!(texts.contains(label), "{label:?} missing");
    }
    // Decade tick labels 10^k as "10" + superscript k.
    for k in ["102", "103", "10-2", "10-1"] {
        assert!(texts.iter().any(|t| t == k), "tick label {k} missing from {texts:?}");
    }
    // Error bars of series 0 are paths in its colour.
    assert!(svg.matches(&format!(r#"stroke="{}" stroke-width="1.5""#, series_color(0).hex())).count() >= 5);
    assert_eq!(chart.try_to_svg().unwrap(), svg);
}

#[test]
fn svg_escapes_and_drops_forbidden_characters() {
    let mut chart = study(1);
    chart.title = "a\u{1}b <&> 'q' \"d\"\nnext\u{FFFF}".into();
    chart.series[0].name = "]]> </text><script>".into();
    let (texts, _) = parse_svg(&chart.to_svg());
    assert!(texts.contains(&"a b <&> 'q' \"d\" next".to_string()), "{texts:?}");
    assert!(texts.contains(&"]]> </text><script>".to_string()));
}

#[test]
fn png_has_right_size_and_every_series_colour() {
    let chart = study(8);
    let (w, h, rgb) = decode_png(&chart.to_png().unwrap());
    assert_eq!((w, h), (plot::WIDTH, plot::HEIGHT));
    assert_eq!(rgb.len(), 1200 * 800 * 3);
    for i in 0..8 {
        let n = count_colour(&rgb, series_color(i));
        assert!(n >= 50, "series {i}: only {n} pixels of {:?}", series_color(i));
    }
    let white = count_colour(&rgb, plot::Rgb(255, 255, 255));
    assert!(white > rgb.len() / 3 / 2 && white < rgb.len() / 3, "{white} white pixels");
}

#[test]
fn png_sizes() {
    let chart = study(3);
    for (w, h) in [(400, 300), (1600, 1000), (600, 900)] {
        let (dw, dh, rgb) = decode_png(&chart.to_png_sized(w, h).unwrap());
        assert_eq!((dw, dh), (w, h));
        for i in 0..3 {
            assert!(count_colour(&rgb, series_color(i)) > 0, "{w}x{h}: series {i} invisible");
        }
    }
    for (w, h) in [(0, 0), (399, 800), (1200, 5000)] {
        assert!(matches!(chart.to_png_sized(w, h), Err(PlotError::Size { .. })));
    }
}

#[test]
fn writes_are_atomic_and_checked_first() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("out.svg");
    let png_path = dir.path().join("out.png");
    let chart = study(2);
    chart.write_svg(&svg).unwrap();
    chart.write_png(&png_path).unwrap();
    assert_eq!(std::fs::read_to_string(&svg).unwrap(), chart.to_svg());
    let (w, h, _) = decode_png(&std::fs::read(&png_path).unwrap());
    assert_eq!((w, h), (1200, 800));
    // Overwrite in place; no temporary files are left.
    study(3).write_svg(&svg).unwrap();
    let files: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(files.len(), 2, "{files:?}");

    // An empty chart is refused before the file is touched.
    let empty = Chart::default();
    assert!(matches!(empty.write_svg(&svg), Err(PlotError::NoData(_))));
    assert_eq!(std::fs::read_to_string(&svg).unwrap(), study(3).to_svg());
    assert!(matches!(empty.write_png(&dir.path().join("new.png")), Err(PlotError::NoData(_))));
    assert!(!dir.path().join("new.png").exists());

    // A missing directory is a write error.
    let err = chart.write_svg(Path::new("/nonexistent-dir-for-plot-test/x.svg")).unwrap_err();
    assert!(matches!(err, PlotError::Write(_)), "{err}");
}

#[test]
fn log_ticks_are_decades() {
    assert_eq!(log_ticks(30.0, 3e5).major, [1e2, 1e3, 1e4, 1e5]);
    assert_eq!(log_ticks(3e5, 30.0).major, [1e2, 1e3, 1e4, 1e5]);
    assert_eq!(log_ticks(1e-3, 1.0).major, [1e-3, 1e-2, 1e-1, 1.0]);
    assert_eq!(log_ticks(0.0009, 0.011).major, [1e-3, 1e-2]);
    let t = log_ticks(30.0, 3e5);
    for m in [40.0, 200.0, 900.0, 2e4, 3e5] {
        assert!(t.minor.iter().any(|&v| (v / m - 1.0).abs() < 1e-12), "minor tick {m} missing");
    }
    assert!(t.minor.iter().all(|&v| (30.0..=3e5).contains(&v)));
    // Wide ranges label at most 8 or 9 decades, evenly.
    let wide = log_ticks(1e-300, 1e300);
    assert!(wide.major.len() >= 5 && wide.major.len() <= 9, "{:?}", wide.major);
    let exps: Vec<i32> = wide.major.iter().map(|v| v.log10().round() as i32).collect();
    assert!(exps.windows(2).all(|w| w[1] - w[0] == exps[1] - exps[0]));
    // Less than two decades: 1-2-5 ticks, then linear ticks.
    assert_eq!(log_ticks(0.015, 0.12).major, [0.02, 0.05, 0.1]);
    let narrow = log_ticks(0.031, 0.048);
    assert!(narrow.major.len() >= 2 && narrow.major.iter().all(|&v| (0.031..=0.048).contains(&v)), "{narrow:?}");
    // Invalid ranges give no ticks.
    for (lo, hi) in [(0.0, 10.0), (-1.0, 10.0), (f64::NAN, 10.0), (1.0, f64::INFINITY)] {
        assert_eq!(log_ticks(lo, hi), plot::Ticks::default(), "{lo}..{hi}");
    }
}

#[test]
fn linear_ticks_are_nice() {
    assert_eq!(linear_ticks(0.0, 1.0).major, [0.0, 0.2, 0.4, 0.6, 0.8, 1.0]);
    assert_eq!(linear_ticks(-3.0, 7.0).major, [-2.0, 0.0, 2.0, 4.0, 6.0]);
    assert_eq!(linear_ticks(0.13, 0.47).major, [0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45]);
    assert_eq!(linear_ticks(5.0, 5.0).major, [5.0]);
    assert!(linear_ticks(f64::NAN, 1.0).major.is_empty());
    assert!(linear_ticks(-f64::MAX, f64::MAX).major.len() <= 2);
}

#[test]
fn empty_or_unplottable_charts_are_errors() {
    let no_series = Chart { log_x: true, log_y: true, ..Chart::default() };
    assert!(matches!(no_series.validate(), Err(PlotError::NoData(_))));
    assert!(matches!(no_series.to_png(), Err(PlotError::NoData(_))));
    assert!(matches!(no_series.try_to_svg(), Err(PlotError::NoData(_))));
    // to_svg still draws something: empty axes with a note.
    let (texts, _) = parse_svg(&no_series.to_svg());
    assert!(texts.iter().any(|t| t.contains("no data")));

    let nan = Chart {
        series: vec![Series { name: "nan".into(), points: vec![(f64::NAN, 1.0), (1.0, f64::INFINITY)], band: None }],
        ..no_series.clone()
    };
    assert!(matches!(nan.validate(), Err(PlotError::NoData(_))));
    let (texts, _) = parse_svg(&nan.to_svg());
    assert!(texts.contains(&"nan".to_string()));

    // Non-positive values vanish on log axes only.
    let mut nonpos = nan.clone();
    nonpos.series[0].points = vec![(1.0, 0.0), (2.0, -1.0)];
    assert!(matches!(nonpos.validate(), Err(PlotError::NoData(_))));
    nonpos.log_y = false;
    assert!(nonpos.validate().is_ok());
    assert!(nonpos.to_png().is_ok());

    let no_points = Chart { series: vec![Series::default()], ..Chart::default() };
    assert!(matches!(no_points.to_png(), Err(PlotError::NoData(_))));

    let mut bad_band = study(2);
    bad_band.series[1].band = Some(vec![(0.1, 0.2)]);
    let err = bad_band.validate().unwrap_err();
    assert!(matches!(err, PlotError::BandLength { points: 5, band: 1, .. }), "{err}");
    parse_svg(&bad_band.to_svg());
}

#[test]
fn skipped_points_break_the_line() {
    let chart = Chart {
        log_x: true,
        log_y: true,
        series: vec![Series {
            name: "gappy".into(),
            points: vec![(1.0, 1.0), (2.0, 2.0), (3.0, -1.0), (4.0, 4.0), (5.0, 5.0), (6.0, f64::NAN), (7.0, 7.0)],
            band: None,
        }],
        ..Chart::default()
    };
    let svg = chart.to_svg();
    assert_eq!(svg.matches("<polyline").count(), 2);
    // Five markers: the legend's plus the five showable points.
    assert_eq!(svg.matches("<circle").count(), 5 + 1);
}

/// Awkward values anywhere never panic, and whatever renders is well-formed.
#[test]
fn garbage_never_panics() {
    let specials = [
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        0.0,
        -0.0,
        -1.0,
        f64::MIN_POSITIVE,
        5e-324,
        f64::MAX,
        -f64::MAX,
        1e300,
        1e-300,
        1.0,
        1.0 + 1e-15,
    ];
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for round in 0..1000 {
        let mut value = || {
            let r = next();
            if r % 3 == 0 {
                specials[(r >> 8) as usize % specials.len()]
            } else {
                ((r >> 11) as f64 / (1u64 << 53) as f64) * 10f64.powi((r % 7) as i32 - 3)
            }
        };
        let series = (0..(round % 4))
            .map(|i| {
                let n = (round * 7 + i) % 6;
                let points: Vec<(f64, f64)> = (0..n).map(|_| (value(), value())).collect();
                let band = (i % 2 == 0).then(|| (0..n).map(|_| (value(), value())).collect());
                Series { name: format!("s{i}"), points, band }
            })
            .collect();
        let chart = Chart {
            title: "t".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            log_x: round % 2 == 0,
            log_y: round % 3 != 0,
            series,
        };
        let svg = chart.to_svg();
        assert!(
            !svg.contains("NaN") && !svg.contains("inf"),
            "round {round}: non-finite coordinate in {chart:?}\n{}",
            svg.lines().filter(|l| l.contains("NaN") || l.contains("inf")).collect::<Vec<_>>().join("\n")
        );
        parse_svg(&svg);
        if round % 25 == 0 {
            match chart.to_png_sized(400, 300) {
                Ok(bytes) => assert_eq!(decode_png(&bytes).0, 400),
                Err(PlotError::NoData(_)) | Err(PlotError::BandLength { .. }) => {}
                Err(e) => panic!("round {round}: {e}"),
            }
        }
    }
}
