//! Insertion order: biased randomized insertion order (BRIO, Amenta, Choi & Rote 2003,
//! "Incremental constructions con BRIO", SoCG) whose rounds are each sorted along a
//! Hilbert curve by recursive median splits (CGAL's `Hilbert_sort_median_3` and
//! `Multiscale_sort`, Delage 2008; Liu, Yan & Devillers 2013 for the analysis of
//! Hilbert-curve insertion orders).
//!
//! Median splits adapt to the point distribution, so strongly clustered inputs (points
//! with exponentially varying spacing) are ordered as well as uniform ones.

use vf_common::rng::{SplitMix64, Stream};

use crate::predicates::Point;

/// A point with its index, sorted together for locality.
#[derive(Clone, Copy)]
pub(crate) struct Item {
    pub p: Point,
    pub index: u32,
}

/// Smallest BRIO round; below it everything is one Hilbert-sorted round.
const MULTISCALE_THRESHOLD: usize = 16;
/// Fraction of a round's points that go to the earlier (sparser) rounds.
const MULTISCALE_RATIO: f64 = 0.25;
/// Hilbert recursion stops at this many points.
const HILBERT_LIMIT: usize = 4;

/// BRIO + Hilbert order of `items`, in place. Deterministic (fixed seed).
///
/// # Complexity
/// O(n log n) time, no allocation.
pub(crate) fn brio_hilbert_sort(items: &mut [Item]) {
    let mut rng = SplitMix64::from_state(Stream::DelaunayInsertion as u64);
    // Fisher–Yates shuffle: the randomisation of BRIO.
    for i in (1..items.len()).rev() {
        let j = rng.below(i + 1);
        items.swap(i, j);
    }
    multiscale(items);
}

fn multiscale(items: &mut [Item]) {
    let mut middle = 0;
    if items.len() >= MULTISCALE_THRESHOLD {
        middle = (items.len() as f64 * MULTISCALE_RATIO) as usize;
        multiscale(&mut items[..middle]);
    }
    hilbert_sort(&mut items[middle..], 0, false, false, false);
}

/// Median split: partitions around the middle element along `axis` (descending if
/// `up`), returning the split position.
fn split(items: &mut [Item], axis: usize, up: bool) -> usize {
    if items.len() < 2 {
        return 0;
    }
    let mid = items.len() / 2;
    if up {
        items.select_nth_unstable_by(mid, |a, b| b.p[axis].total_cmp(&a.p[axis]));
    } else {
        items.select_nth_unstable_by(mid, |a, b| a.p[axis].total_cmp(&b.p[axis]));
    }
    mid
}

/// CGAL's `Hilbert_sort_median_3::sort<x, upx, upy, upz>` with the template parameters
/// made runtime arguments; `upy` and `upz` refer to the axes `x+1` and `x+2` (mod 3).
fn hilbert_sort(items: &mut [Item], x: usize, upx: bool, upy: bool, upz: bool) {
    if items.len() <= HILBERT_LIMIT {
        return;
    }
    let y = (x + 1) % 3;
    let z = (x + 2) % 3;
    let n = items.len();
    let m4 = split(items, x, upx);
    let m2 = split(&mut items[..m4], y, upy);
    let m1 = split(&mut items[..m2], z, upz);
    let m3 = m2 + split(&mut items[m2..m4], z, !upz);
    let m6 = m4 + split(&mut items[m4..], y, !upy);
    let m5 = m4 + split(&mut items[m4..m6], z, upz);
    let m7 = m6 + split(&mut items[m6..n], z, !upz);

    hilbert_sort(&mut items[..m1], z, upz, upx, upy);
    hilbert_sort(&mut items[m1..m2], y, upy, upz, upx);
    hilbert_sort(&mut items[m2..m3], y, upy, upz, upx);
    hilbert_sort(&mut items[m3..m4], x, upx, !upy, !upz);
    hilbert_sort(&mut items[m4..m5], x, upx, !upy, !upz);
    hilbert_sort(&mut items[m5..m6], y, !upy, upz, !upx);
    hilbert_sort(&mut items[m6..m7], y, !upy, upz, !upx);
    hilbert_sort(&mut items[m7..], z, !upz, !upx, upy);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sort_is_a_permutation_and_local() {
        let mut rng = SplitMix64::from_state(7);
        let n = 4096;
        let mut items: Vec<Item> = (0..n)
            .map(|i| Item {
                p: [0, 1, 2].map(|_| (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64),
                index: i as u32,
            })
            .collect();
        let before: f64 = path_length(&items);
        brio_hilbert_sort(&mut items);
        let mut seen: Vec<u32> = items.iter().map(|it| it.index).collect();
        seen.sort_unstable();
        assert!(seen.iter().enumerate().all(|(i, &s)| s as usize == i));
        // The last round (3/4 of the points) is Hilbert-sorted: far shorter path than
        // random order.
        let last = &items[n / 4..];
        assert!(path_length(last) < 0.2 * before * (last.len() as f64 / n as f64));
    }

    fn path_length(items: &[Item]) -> f64 {
        items
            .windows(2)
            .map(|w| {
                let d = [0, 1, 2].map(|k| w[0].p[k] - w[1].p[k]);
                (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
            })
            .sum()
    }
}
