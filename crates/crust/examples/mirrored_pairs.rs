//! Mirrored site pairs across a sphere (Fibonacci lattice): c + (r ± δ)n, inside for r − δ.
//!
//!     cargo run --profile ci -p crust --example mirrored_pairs -- K FRAC [round]

use crust::check::check_crust;
use crust::{Crust, CrustConfig};

fn fib(k: usize) -> Vec<[f64; 3]> {
    let ga = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..k)
        .map(|i| {
            let z = 1.0 - (2.0 * i as f64 + 1.0) / k as f64;
            let rho = (1.0 - z * z).sqrt();
            let phi = ga * i as f64;
            [rho * phi.cos(), rho * phi.sin(), z]
        })
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let ks: Vec<usize> = args.get(1).map_or(vec![64, 256, 1024, 4096], |a| a.split(',').map(|x| x.parse().unwrap()).collect());
    let fracs: Vec<f64> = args.get(2).map_or(vec![0.1, 0.25, 0.5], |a| a.split(',').map(|x| x.parse().unwrap()).collect());
    let round = args.get(3).cloned().unwrap_or_default();
    let (c, r) = ([0.5; 3], 0.3);
    for &k in &ks {
        let spacing = r * (4.0 * std::f64::consts::PI / k as f64).sqrt();
        for &f in &fracs {
            let d = f * spacing;
            let mut sites = Vec::new();
            let mut inside = Vec::new();
            for n in fib(k) {
                for (s, ins) in [(r - d, true), (r + d, false)] {
                    let mut p = [0, 1, 2].map(|j| c[j] + s * n[j]);
                    match round.as_str() {
                        "f32" => p = p.map(|x| x as f32 as f64),
                        "grid" => p = p.map(|x| (x * 1e6).round() / 1e6),
                        _ => {}
                    }
                    sites.push(p);
                    inside.push(ins);
                }
            }
            let t = std::time::Instant::now();
            let res = Crust::extract(&sites, &inside, &CrustConfig::default());
            match res {
                Err(e) => println!("K {k} frac {f} {round}: extract error {e}"),
                Ok(cr) => match check_crust(&cr.mesh) {
                    Ok(_) if true => println!("K {k} frac {f} {round}: ok ({} tris, {:?})", cr.mesh.triangles.len(), t.elapsed()),
                    Ok(_) | Err(_) => {
                        let m = &cr.mesh;
                        let mut hist = [0usize; 40];
                        for t in &m.triangles { for q in 0..3 {
                            let (a, b) = (m.positions[t[q] as usize], m.positions[t[(q+1)%3] as usize]);
                            let d = (0..3).map(|j| (a[j]-b[j]).abs()).fold(0.0f64, f64::max);
                            let l = if d == 0.0 { 0 } else { ((d.log2() + 60.0).max(1.0) as usize).min(39) };
                            hist[l] += 1;
                        }}
                        println!("edge length hist (log2+60): {:?}", hist);
                        let e = check_crust(m).err().unwrap_or_default();
                        println!("K {k} frac {f} {round}: FAIL {e} ({} tris) {:?}", cr.mesh.triangles.len(), cr.stats);
                        let (_, hit) = crust::check::self_intersections(&cr.mesh, true);
                        if let Some((a, b)) = hit {
                            for t in [a, b] {
                                let tri = cr.mesh.triangles[t];
                                println!("  tri {t} {:?}", tri);
                                for v in tri { println!("    {:?}", cr.mesh.positions[v as usize]); }
                            }
                        }
                    }
                },
            }
        }
    }
}
