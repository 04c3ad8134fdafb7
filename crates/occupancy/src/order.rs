//! Spatially coherent processing order for query batches.
//!
//! Batch functions visit queries in Morton (Z-order) order of their coordinates, so that
//! consecutive queries traverse the same BVH nodes (cache locality) and the closest-point
//! search can start from the previous query's triangle (a tight initial bound). Results
//! are written back in the caller's order and do not depend on the thread count: the
//! order and its fixed-size chunks depend only on the queries.

use rayon::prelude::*;

use vf_common::vec3::V3;

/// Spreads the low 21 bits of `x` to every third bit.
fn spread(mut x: u64) -> u64 {
    x &= 0x1f_ffff;
    x = (x | (x << 32)) & 0x001f_0000_0000_ffff;
    x = (x | (x << 16)) & 0x001f_0000_ff00_00ff;
    x = (x | (x << 8)) & 0x100f_00f0_0f00_f00f;
    x = (x | (x << 4)) & 0x10c3_0c30_c30c_30c3;
    x = (x | (x << 2)) & 0x1249_2492_4924_9249;
    x
}

/// Permutation of `0..queries.len()` sorting the queries by Morton code (ties by index).
///
/// - `queries`: #Q×3 f64, finite.
/// - returns: #Q u32 indices into `queries`.
pub fn morton_order(queries: &[V3]) -> Vec<u32> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for q in queries {
        for k in 0..3 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    let scale: Vec<f64> = (0..3)
        .map(|k| {
            let ext = hi[k] - lo[k];
            if ext > 0.0 {
                ((1u64 << 21) - 1) as f64 / ext
            } else {
                0.0
            }
        })
        .collect();
    let mut keyed: Vec<(u64, u32)> = queries
        .par_iter()
        .enumerate()
        .map(|(i, q)| {
            let mut code = 0u64;
            for k in 0..3 {
                let cell = ((q[k] - lo[k]) * scale[k]) as u64;
                code |= spread(cell) << k;
            }
            (code, i as u32)
        })
        .collect();
    keyed.par_sort_unstable();
    keyed.into_iter().map(|(_, i)| i).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn order_is_a_permutation_and_groups_neighbours() {
        let mut pts = Vec::new();
        for i in 0..1000 {
            let x = (i * 7919 % 1000) as f64 / 1000.0;
            pts.push([x, (x * 13.0).fract(), (x * 31.0).fract()]);
        }
        let order = morton_order(&pts);
        let mut seen = vec![false; pts.len()];
        for &i in &order {
            assert!(!seen[i as usize]);
            seen[i as usize] = true;
        }
        // Consecutive points in Morton order are closer on average than in input order.
        let step = |ord: &[u32]| -> f64 {
            ord.windows(2)
                .map(|w| {
                    let (a, b) = (pts[w[0] as usize], pts[w[1] as usize]);
                    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt()
                })
                .sum::<f64>()
        };
        let identity: Vec<u32> = (0..pts.len() as u32).collect();
        assert!(step(&order) < 0.5 * step(&identity));
    }
}
