//! Edge cases for eyeballing: `cargo run -p plot --example gallery -- OUT_DIR` writes
//! `gallery_*.png` and `.svg` (linear axes, a narrow log range, a single point, long text,
//! the smallest size, many series).

use std::path::PathBuf;

use plot::{Chart, PlotError, Series};

fn series(name: &str, points: Vec<(f64, f64)>) -> Series {
    Series { name: name.into(), points, band: None }
}

fn main() -> Result<(), PlotError> {
    let dir = PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| ".".into()));
    let linear = Chart {
        title: "Linear axes with negative values and error bars".into(),
        x_label: "iteration".into(),
        y_label: "loss".into(),
        log_x: false,
        log_y: false,
        series: vec![
            Series {
                name: "train".into(),
                points: (0..20).map(|i| (i as f64 * 50.0, 3.0 * (-(i as f64) / 5.0).exp() - 0.4)).collect(),
                band: Some(
                    (0..20)
                        .map(|i| (3.0 * (-(i as f64) / 5.0).exp() - 0.6, 3.0 * (-(i as f64) / 5.0).exp() - 0.2))
                        .collect(),
                ),
            },
            series("validation", (0..20).map(|i| (i as f64 * 50.0, 3.2 * (-(i as f64) / 6.0).exp() - 0.3)).collect()),
        ],
    };
    let narrow = Chart {
        title: "Narrow log range".into(),
        x_label: "parameters".into(),
        y_label: "distance".into(),
        log_x: true,
        log_y: true,
        series: vec![
            series("a", vec![(100.0, 0.031), (150.0, 0.036), (220.0, 0.048)]),
            series("b", vec![(110.0, 0.033), (200.0, 0.04)]),
        ],
    };
    let single = Chart {
        title: "One point".into(),
        x_label: "x".into(),
        y_label: "y".into(),
        log_x: true,
        log_y: true,
        series: vec![Series { name: "only".into(), points: vec![(1000.0, 0.01)], band: Some(vec![(0.0, 0.02)]) }],
    };
    let long = Chart {
        title: "A very long title that goes on and on to see what happens when it does not fit into the width of the picture at all".into(),
        x_label: "number of parameters (sites × 4 floats, plus per-site labels, plus the global offset)".into(),
        y_label: "symmetric Hausdorff distance in the unit cube after normalisation".into(),
        log_x: true,
        log_y: true,
        series: vec![
            series("A method with an extraordinarily long descriptive name (v2, tuned)", vec![(10.0, 1e-5), (1e7, 1e2)]),
            series("Ünïcödé — ok?", vec![(20.0, 1e-4), (1e6, 10.0)]),
        ],
    };
    let many = Chart {
        title: "Many series".into(),
        x_label: "x".into(),
        y_label: "y".into(),
        log_x: false,
        log_y: true,
        series: (0..12)
            .map(|i| {
                series(&format!("series {i}"), (0..8).map(|j| (j as f64, (1.0 + i as f64) * 1.5f64.powi(j))).collect())
            })
            .collect(),
    };
    for (name, chart, size) in [
        ("linear", &linear, (1200, 800)),
        ("narrow", &narrow, (1200, 800)),
        ("single", &single, (1200, 800)),
        ("long", &long, (1200, 800)),
        ("small", &narrow, (400, 300)),
        ("many", &many, (1200, 800)),
    ] {
        chart.write_svg(&dir.join(format!("gallery_{name}.svg")))?;
        std::fs::write(dir.join(format!("gallery_{name}.png")), chart.to_png_sized(size.0, size.1)?).expect("write");
    }
    println!("wrote gallery_*.{{svg,png}} to {}", dir.display());
    Ok(())
}
