//! Times check_crust on the crust of ball-labelled uniform sites.
use crust::{check::check_crust, Crust, CrustConfig};
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
    for _ in 0..3 {
        let t = Instant::now();
        let c = Crust::extract(&pts, &inside, &CrustConfig::default()).unwrap();
        let te = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let chk = check_crust(&c.mesh).unwrap();
        println!("extract {te:.3} s, check {:.3} s, {} tris, {} pairs", t.elapsed().as_secs_f64(), c.mesh.triangles.len(), chk.num_pairs_tested);
    }
}
