//! Times the certified Hausdorff interval (BVH builds included, mesh loading excluded) and
//! the libigl-compatible value on two mesh files; prints one JSON object.
//!
//!     cargo run --release -p metrics --example hausdorff_timing -- A.obj B.obj [REL_TOL] [REPEATS]
//!
//! Used by `benches/compare_hausdorff.py`, which times `igl.hausdorff` in the same run.

use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        eprintln!("usage: hausdorff_timing A B [REL_TOL] [REPEATS]");
        std::process::exit(2);
    }
    let a = mesh_io::read_mesh(std::path::Path::new(&args[1])).unwrap_or_else(|e| {
        eprintln!("error: {e}");
        std::process::exit(2)
    });
    let b = mesh_io::read_mesh(std::path::Path::new(&args[2])).unwrap_or_else(|e| {
        eprintln!("error: {e}");
        std::process::exit(2)
    });
    let rel: f64 = args.get(3).map(|s| s.parse().expect("REL_TOL")).unwrap_or(1e-6);
    let repeats: usize = args.get(4).map(|s| s.parse().expect("REPEATS")).unwrap_or(3);
    let opts = metrics::CertifiedOptions { rel_tolerance: rel, ..Default::default() };
    let mut best_cert = f64::INFINITY;
    let mut best_igl = f64::INFINITY;
    let mut result = None;
    let mut igl = 0.0;
    for _ in 0..repeats {
        let t = Instant::now();
        let r = metrics::hausdorff_certified(&a, &b, &opts).expect("certified");
        best_cert = best_cert.min(t.elapsed().as_secs_f64());
        result = Some(r);
        let t = Instant::now();
        igl = metrics::hausdorff_libigl(&a, &b).expect("libigl");
        best_igl = best_igl.min(t.elapsed().as_secs_f64());
    }
    let r = result.expect("at least one repeat");
    let out = serde_json::json!({
        "faces": [a.triangles.len(), b.triangles.len()],
        "certified_seconds": best_cert,
        "libigl_compatible_seconds": best_igl,
        "libigl_compatible": igl,
        "threads": rayon::current_num_threads(),
        "interval": r,
    });
    println!("{}", serde_json::to_string_pretty(&out).expect("json"));
}
