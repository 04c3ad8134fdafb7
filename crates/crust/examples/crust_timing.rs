//! Times the crust of ball-labelled uniform sites against its Delaunay tetrahedralization,
//! best of 5 runs each, and prints the ratio (docs/performance.md).
//!
//!     cargo run --release -p crust --example crust_timing -- 100000

use crust::{Crust, CrustConfig};
use std::time::Instant;

fn main() {
    let k: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(100_000);
    let mut s = 0x9e37_79b9_7f4a_7c15u64;
    let mut r = || {
        s ^= s >> 12;
        s ^= s << 25;
        s ^= s >> 27;
        ((s.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    let pts: Vec<[f64; 3]> = (0..k).map(|_| [r(), r(), r()]).collect();
    let inside: Vec<bool> =
        pts.iter().map(|p| (p[0] - 0.5).powi(2) + (p[1] - 0.5).powi(2) + (p[2] - 0.5).powi(2) < 0.35 * 0.35).collect();
    let best = |f: &mut dyn FnMut()| {
        (0..5)
            .map(|_| {
                let t = Instant::now();
                f();
                t.elapsed().as_secs_f64()
            })
            .fold(f64::INFINITY, f64::min)
    };
    let dt = best(&mut || {
        delaunay3::Delaunay3::new(&pts).unwrap();
    });
    let mut tris = 0;
    let crust = best(&mut || {
        tris = Crust::extract(&pts, &inside, &CrustConfig::default()).unwrap().mesh.triangles.len();
    });
    println!("sites {k} (ball-labelled, {} inside): delaunay {dt:.3} s, crust (including its delaunay) {crust:.3} s, ratio {:.2}, {tris} triangles", inside.iter().filter(|&&b| b).count(), crust / dt);
}
