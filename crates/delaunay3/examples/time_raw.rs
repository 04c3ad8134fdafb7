//! Times only the triangulation of a point file, for `benches/compare_delaunay.py`.
//!
//! Usage: `time_raw POINTS.f64 [--validate]` where the file holds #N×3 f64
//! little-endian, row-major (numpy's `points.astype('<f8').tofile(path)`); or
//! `time_raw --uniform N` to generate uniform points. Prints one JSON line: CPU and wall
//! seconds of `Delaunay3::new` only (construction is single-threaded) (file reading excluded), the finite tetrahedron
//! count, and the peak-RSS growth during construction in bytes.

use delaunay3::Delaunay3;
use std::time::Instant;

fn cpu_seconds() -> f64 {
    // Nanosecond on-CPU time of this (the only busy) thread, when the kernel has
    // schedstats; otherwise utime + stime in clock ticks.
    if let Ok(s) = std::fs::read_to_string("/proc/thread-self/schedstat") {
        if let Some(ns) = s.split_whitespace().next().and_then(|x| x.parse::<f64>().ok()) {
            if ns > 0.0 {
                return ns * 1e-9;
            }
        }
    }
    // utime + stime of this process, in clock ticks (fields 14 and 15 of /proc/self/stat).
    let s = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = s.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = after.split_whitespace().collect();
    let ticks: f64 = f.get(11).and_then(|x| x.parse().ok()).unwrap_or(0.0)
        + f.get(12).and_then(|x| x.parse::<f64>().ok()).unwrap_or(0.0);
    ticks / 100.0
}

fn status_kib(key: &str) -> u64 {
    let s = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    s.lines()
        .find(|l| l.starts_with(key))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|x| x.parse().ok())
        .unwrap_or(0)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let points: Vec<[f64; 3]> = if args.get(1).map(String::as_str) == Some("--uniform") {
        let n: usize = args[2].parse().expect("N");
        let mut s = 1u64;
        let mut next = move || {
            s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = s;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..n).map(|_| [next(), next(), next()]).collect()
    } else {
        let bytes = std::fs::read(&args[1]).expect("read points file");
        assert!(bytes.len() - bytes.len() / 24 * 24 == 0, "file size is not a multiple of 24 bytes");
        bytes
            .chunks_exact(24)
            .map(|c| {
                let f = |k: usize| f64::from_le_bytes(c[8 * k..8 * k + 8].try_into().unwrap());
                [f(0), f(1), f(2)]
            })
            .collect()
    };
    let validate = args.iter().any(|a| a == "--validate");
    let rss0 = status_kib("VmRSS:");
    let (c0, w0) = (cpu_seconds(), Instant::now());
    let dt = Delaunay3::new(&points).expect("triangulation");
    let (c1, w1) = (cpu_seconds(), w0.elapsed().as_secs_f64());
    let hwm = status_kib("VmHWM:");
    let mut validate_s = -1.0;
    if validate {
        let t = Instant::now();
        dt.validate().expect("valid");
        validate_s = t.elapsed().as_secs_f64();
    }
    println!(
        "{{\"n\": {}, \"num_vertices\": {}, \"num_finite_tets\": {}, \"cpu_seconds\": {:.3}, \"wall_seconds\": {:.3}, \"peak_rss_growth_bytes\": {}, \"validate_seconds\": {:.3}}}",
        points.len(),
        dt.num_vertices(),
        dt.num_finite_tets(),
        c1 - c0,
        w1,
        hwm.saturating_sub(rss0) * 1024,
        validate_s
    );
}
