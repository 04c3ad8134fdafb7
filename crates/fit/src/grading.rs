//! Spacing graded by how much a sheet bends: where the thin shell's triplets must lie
//! closer together so a thin band keeps no hole, and where they may lie farther apart.
//!
//! A triplet (inside at p, outside at p ± 2h·n) carries the band exactly while the sheet
//! stays within h of p's tangent plane: a sheet point x nearer p than any other triplet's
//! centre is then nearer p's inside site than p's outside sites. Where the sheet leaves
//! the tangent plane by more than h inside that distance, an outside site wins and the
//! band has a hole there (the steps of about s²κ/2 of `target::BAND_FACTORS`' doc). So
//! each candidate point gets the largest spacing over which its neighbourhood bends less
//! than a share of h, and a Poisson-disk pass with these radii (finest first) places the
//! triplets; flat parts, which hold at any spacing, give up sites to curved ones.
//!
//! Written here rather than taken from a crate: the graded pass is the workspace's
//! greedy Poisson-disk ([`soft_voronoi::init::greedy_disk_around`]) run level by level,
//! and the bending measure is particular to the shell's triplets.

use rayon::prelude::*;
use soft_voronoi::init::greedy_disk_around;
use soft_voronoi::SiteIndex;

/// Spacing levels below the widest: each √2 narrower than the one before, down to 1/8
/// of the widest (a quarter of the uniform spacing).
pub const LEVELS: usize = 7;

/// How far the sheet may leave a triplet's tangent plane within its spacing, as a share
/// of h.
pub const BEND_SHARE: f64 = 0.7;

/// The share of a shell's candidate points that [`spread`] and the shell's [`bending`]
/// take as neighbours: every fourth.
pub const CLOUD_STRIDE: usize = 4;

/// The spacing ladder from `widest` down: widest · 2^(−l/2) for l = 0 … LEVELS − 1.
pub fn ladder(widest: f64) -> [f64; LEVELS] {
    std::array::from_fn(|l| widest * 0.5f64.powf(l as f64 / 2.0))
}

/// For each query point q (with a unit direction n, either orientation), how far the cloud
/// leaves q's plane (or line) within each radius of `radii` (widest first): the largest
/// |⟨x − q, n⟩| over cloud points x within the radius — for a sheet and its normal, exactly
/// the distance of the sheet from q's tangent plane that opens a hole when it passes h.
/// (A measure by the angle between the normals, |x − q|·sin(θ/2), is exact on a circle
/// but half the distance across a crease: libigl's beetle, with h chosen by it, kept holes
/// where the sheet stood 1.0 h off a triplet's plane.)
pub fn bending(
    queries: &[[f64; 3]],
    query_dirs: &[[f64; 3]],
    cloud: &[[f64; 3]],
    radii: &[f64; LEVELS],
) -> Vec<[f64; LEVELS]> {
    if cloud.is_empty() {
        return vec![[0.0; LEVELS]; queries.len()];
    }
    let index = SiteIndex::new(cloud);
    queries
        .par_iter()
        .zip(query_dirs)
        .map_init(Vec::new, |near, (&q, &n)| {
            let mut out = [0.0f64; LEVELS];
            let d_min = index.candidates(cloud, q, radii[0], near);
            for &(j, d) in near.iter() {
                if d > radii[0] + d_min {
                    continue;
                }
                let x = cloud[j as usize];
                let bend = ((x[0] - q[0]) * n[0] + (x[1] - q[1]) * n[1] + (x[2] - q[2]) * n[2]).abs();
                for (l, r) in radii.iter().enumerate() {
                    if d <= *r {
                        out[l] = out[l].max(bend);
                    }
                }
            }
            // Bending within a radius never exceeds bending within a wider one.
            for l in (0..LEVELS - 1).rev() {
                out[l] = out[l].max(out[l + 1]);
            }
            out
        })
        .collect()
}

/// Each point's bending per radius (from [`bending`], of the same points) raised to the
/// largest bending of any point within that radius, at that radius: a spacing r taken
/// where this stays within the limit keeps every point of the sheet within r of *any*
/// triplet centre nearby close to that centre's plane, not only to the point's own. The
/// Poisson-disk pass guarantees a centre within a candidate's own radius, but the nearest
/// centre may be one of a finer level whose own radius does not reach the candidate (on
/// libigl's beetle, 1,158 of 98,000 candidates were left in holes so).
///
/// The neighbours are every [`CLOUD_STRIDE`]th point.
pub fn spread(points: &[[f64; 3]], bend: &[[f64; LEVELS]], radii: &[f64; LEVELS]) -> Vec<[f64; LEVELS]> {
    if points.is_empty() {
        return Vec::new();
    }
    let cloud: Vec<[f64; 3]> = points.iter().step_by(CLOUD_STRIDE).copied().collect();
    let index = SiteIndex::new(&cloud);
    points
        .par_iter()
        .map_init(Vec::new, |near, &q| {
            let mut out = [0.0f64; LEVELS];
            let d_min = index.candidates(&cloud, q, radii[0], near);
            for &(j, d) in near.iter() {
                if d > radii[0] + d_min {
                    continue;
                }
                let b = &bend[j as usize * CLOUD_STRIDE];
                for (l, r) in radii.iter().enumerate() {
                    if d <= *r {
                        out[l] = out[l].max(b[l]);
                    }
                }
            }
            out
        })
        .collect()
}

/// The widest radius of `radii` (widest first) within which `bend` stays at most `limit`;
/// the narrowest when none does.
pub fn widest_flat(bend: &[f64; LEVELS], radii: &[f64; LEVELS], limit: f64) -> f64 {
    (0..LEVELS).find(|&l| bend[l] <= limit).map_or(radii[LEVELS - 1], |l| radii[l])
}

/// Greedy Poisson-disk subset with a radius per point: `seeds` are kept first, then the
/// points by increasing radius (in order within one radius), each kept when no point kept
/// before lies within its radius. Finest first, so the points that must be close are
/// placed before wider ones claim their room.
pub fn graded_subset(seeds: &[[f64; 3]], points: &[[f64; 3]], radius: &[f64]) -> Vec<u32> {
    let mut levels: Vec<f64> = radius.to_vec();
    levels.sort_by(f64::total_cmp);
    levels.dedup();
    let mut kept_at: Vec<[f64; 3]> = seeds.to_vec();
    let mut kept = Vec::new();
    for r in levels {
        let ids: Vec<u32> = (0..points.len() as u32).filter(|&i| radius[i as usize] == r).collect();
        let pts: Vec<[f64; 3]> = ids.iter().map(|&i| points[i as usize]).collect();
        for j in greedy_disk_around(&kept_at, &pts, r) {
            kept.push(ids[j as usize]);
            kept_at.push(pts[j as usize]);
        }
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_circle_bends_by_its_sagitta() {
        // Points on a circle of radius 0.2 about (0.5, 0.5), directions along the radius.
        let (c, rho) = ([0.5, 0.5, 0.5], 0.2);
        let n = 20_000;
        let pts: Vec<[f64; 3]> = (0..n)
            .map(|i| {
                let t = i as f64 / n as f64 * std::f64::consts::TAU;
                [c[0] + rho * t.cos(), c[1] + rho * t.sin(), c[2]]
            })
            .collect();
        let dirs: Vec<[f64; 3]> = (0..n)
            .map(|i| {
                let t = i as f64 / n as f64 * std::f64::consts::TAU;
                [t.cos(), t.sin(), 0.0]
            })
            .collect();
        let radii = ladder(0.08);
        let b = bending(&pts[..1], &dirs[..1], &pts, &radii);
        for (l, r) in radii.iter().enumerate() {
            // The farthest point within chord r lies r²/(2ρ) off the tangent line.
            let sagitta = r * r / (2.0 * rho);
            assert!((b[0][l] - sagitta).abs() < 0.05 * sagitta, "level {l}: {} vs {sagitta}", b[0][l]);
        }
        assert_eq!(widest_flat(&b[0], &radii, 0.5 * radii[2] * radii[2] / (2.0 * rho) + 1e-9), radii[3]);
    }

    #[test]
    fn a_crease_bends_by_the_distance_across_it() {
        // Two half-planes meeting at a right angle along the line x = 0.5, z = 0.5: the
        // horizontal one (z = 0.5, x < 0.5) and the vertical one (x = 0.5, z > 0.5).
        let mut pts = Vec::new();
        for i in 0..60 {
            for j in 0..60 {
                let (t, y) = (i as f64 * 0.004, 0.3 + j as f64 * 0.004);
                pts.push([0.5 - t, y, 0.5]);
                pts.push([0.5, y, 0.5 + t]);
            }
        }
        let query = [[0.5, 0.42, 0.5], [0.3, 0.42, 0.5]];
        let up = [[0.0, 0.0, 1.0]; 2];
        let radii = ladder(0.2);
        let b = bending(&query, &up, &pts, &radii);
        for (l, r) in radii.iter().enumerate() {
            // On the crease: the vertical half-plane rises r within r. A point 0.2 from it
            // sees the rise only beyond 0.2 (none within these radii but the widest).
            assert!((b[0][l] - r.min(0.236)).abs() < 0.005, "level {l}: {}", b[0][l]);
            assert!(b[1][l] < 1e-12 || l == 0, "level {l}: {}", b[1][l]);
        }
        // Spread: the far point takes the crease's bending within reach of it.
        let at: Vec<[f64; 3]> = query.to_vec();
        let s = spread(&at, &b, &radii);
        assert_eq!(s[0], b[0]);
        assert!(s[1][0] >= b[0][0] && s[1][1] == b[1][1]);
    }

    #[test]
    fn the_finest_points_keep_their_spacing() {
        // A row of points 0.001 apart: the left half at radius 0.01, the right at 0.04.
        let pts: Vec<[f64; 3]> = (0..400).map(|i| [0.3 + 0.001 * i as f64, 0.5, 0.5]).collect();
        let radius: Vec<f64> = (0..400).map(|i| if i < 200 { 0.01 } else { 0.04 }).collect();
        let kept = graded_subset(&[], &pts, &radius);
        let fine = kept.iter().filter(|&&i| i < 200).count();
        let wide = kept.len() - fine;
        assert!((19..=21).contains(&fine), "{fine}");
        assert!((4..=6).contains(&wide), "{wide}");
        // No kept point lies within the radius of one kept before it.
        for (a, &i) in kept.iter().enumerate() {
            for &j in &kept[..a] {
                let d = (pts[i as usize][0] - pts[j as usize][0]).abs();
                assert!(d >= radius[j as usize].min(radius[i as usize]) - 1e-12);
            }
        }
    }
}
