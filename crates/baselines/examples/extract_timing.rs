//! Times `Mlp::eval_grid` of an (untrained) OccNet decoder and `marching_cubes` of a
//! sphere's signed distance on the same grid; prints one JSON line.
//!
//!     cargo run --release -p baselines --example extract_timing -- [width] [depth] [res]
//!
//! Defaults: 256 5 128.

use baselines::{marching_cubes, DecoderConfig, Inside, McOptions};
use std::time::Instant;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let arg = |i: usize, d: usize| a.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
    let (width, depth, res) = (arg(1, 256), arg(2, 5), arg(3, 128));
    let m = baselines::Decoder::new(DecoderConfig::occnet(width, depth), 0).expect("config");
    let t = Instant::now();
    let grid = m.eval_grid(res).expect("grid");
    let eval_s = t.elapsed().as_secs_f64();
    assert_eq!(grid.len(), res * res * res);
    let h = 1.0 / (res - 1) as f64;
    let sphere = ndarray::Array3::from_shape_fn((res, res, res), |(i, j, k)| {
        let p = [i, j, k].map(|c| c as f64 * h - 0.5);
        (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() - 0.35
    });
    let t = Instant::now();
    let mesh =
        marching_cubes(sphere.view(), &McOptions { spacing: [h; 3], inside: Inside::Below, ..Default::default() })
            .expect("mc");
    let mc_s = t.elapsed().as_secs_f64();
    let rep = mesh_io::TopologyReport::of(&mesh);
    println!(
        "{{\"width\":{width},\"depth\":{depth},\"res\":{res},\"params\":{},\"eval_grid_s\":{eval_s:.3},\"points_per_s\":{:.0},\"marching_cubes_s\":{mc_s:.3},\"vertices\":{},\"triangles\":{},\"closed\":{},\"genus\":{:?}}}",
        m.num_params(),
        (res * res * res) as f64 / eval_s,
        mesh.positions.len(),
        mesh.triangles.len(),
        rep.is_closed,
        rep.genus
    );
}
