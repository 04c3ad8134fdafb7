//! Writes a demo of the sphere-study chart: `cargo run -p plot --example sphere_demo -- OUT_DIR`.

use std::path::PathBuf;

fn main() -> Result<(), plot::PlotError> {
    let dir = PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| ".".into()));
    // Made-up numbers shaped like the study: error falls roughly as params^(-1/2).
    let params: [f64; 6] = [24.0, 96.0, 384.0, 1536.0, 6144.0, 24576.0];
    let line = |c: f64, p: f64, noise: f64| -> Vec<(f64, f64)> {
        params
            .iter()
            .enumerate()
            .map(|(i, &n)| (n, c * n.powf(-p) * (1.0 + noise * ((i as f64) * 1.7).sin())))
            .collect()
    };
    let voronoi = line(0.9, 0.5, 0.1);
    let band = voronoi.iter().map(|&(_, y)| (y * 0.8, y * 1.25)).collect();
    let chart = plot::Chart {
        title: "Sphere of radius 0.35: Hausdorff distance vs parameters".into(),
        x_label: "parameters".into(),
        y_label: "Hausdorff distance (unit cube)".into(),
        log_x: true,
        log_y: true,
        series: vec![
            plot::Series { name: "Voronoi (3K)".into(), points: voronoi, band: Some(band) },
            plot::Series { name: "Marching cubes".into(), points: line(0.6, 0.33, 0.05), band: None },
            plot::Series { name: "Occupancy grid".into(), points: line(1.5, 0.33, 0.0), band: None },
            plot::Series {
                name: "Mesh decimation (QEM)".into(),
                points: vec![(30.0, 0.2), (120.0, f64::NAN), (480.0, 0.012), (1920.0, 0.004), (7680.0, 0.0011)],
                band: None,
            },
            plot::Series { name: "Point sampling & <fit>".into(), points: line(0.3, 0.4, 0.2), band: None },
            plot::Series { name: "Spheres".into(), points: line(0.2, 0.6, 0.1), band: None },
            plot::Series { name: "Baseline".into(), points: line(0.05, 0.2, 0.0), band: None },
            plot::Series { name: "Eighth".into(), points: line(2.0, 0.7, 0.0), band: None },
        ],
    };
    chart.write_svg(&dir.join("sphere_demo.svg"))?;
    chart.write_png(&dir.join("sphere_demo.png"))?;
    println!("wrote {}", dir.join("sphere_demo.{svg,png}").display());
    Ok(())
}
