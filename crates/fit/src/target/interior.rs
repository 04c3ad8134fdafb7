//! Interior surface: the input's faces that do not bound the winding solid (overlapping
//! bodies, doubled faces), left out of the surface samples.

use soft_voronoi::{Solid, TrainingData};

/// Surface samples probed first to decide whether the pool has interior surface at all.
pub(super) const INTERIOR_PROBE: usize = 20_000;
/// Below this share of interior surface (on the probe), the pool is kept whole. Bodies
/// that overlap put a large share of the surface inside the solid (cad_union 52%, the
/// soup 29%), and leaving it out cleans their crusts; a few percent is mostly where parts
/// nearly coincide (the teapots' spout and handle, doubled patches of the dragon and the
/// snowden scan: 2.5–2.9%), where those samples still lie next to the boundary and
/// leaving them out made the benchmark's figures no better (snowden's Chamfer distance
/// 0.055% → 0.064%). Probing the whole pool also costs two labels a sample.
pub(super) const INTERIOR_MIN_SHARE: f64 = 0.05;
/// The probes' offset to either side of a surface sample, as a fraction of the diagonal:
/// far above the rounding of the coordinates, far below any feature the sites resolve.
pub(super) const SIDE_OFFSET: f64 = 1e-5;

/// Leaves out of `data.surface` (and its normals) the samples that are not on the
/// boundary of `solid` — the same label at x + εn and x − εn — unless the first
/// [`INTERIOR_PROBE`] show less than [`INTERIOR_MIN_SHARE`] of them, or fewer than 1% of
/// the samples would remain. Returns the share of such samples (on the whole pool when it
/// was probed, else on the probe) and how many were dropped.
pub(super) fn drop_interior_surface(solid: &dyn Solid, data: &mut TrainingData, diagonal: f64) -> (f64, usize) {
    let n = data.surface.len();
    if n == 0 || data.normals.len() != n {
        return (0.0, 0);
    }
    let eps = SIDE_OFFSET * diagonal;
    let interior = |range: std::ops::Range<usize>| -> Vec<bool> {
        let mut probes = Vec::with_capacity(2 * range.len());
        for i in range.clone() {
            let (x, nx) = (data.surface[i], data.normals[i]);
            probes.push([0, 1, 2].map(|c| x[c] + eps * nx[c]));
            probes.push([0, 1, 2].map(|c| x[c] - eps * nx[c]));
        }
        let labels = solid.inside(&probes);
        // A sample without a normal (degenerate face) cannot be probed: kept.
        range.zip(labels.chunks_exact(2)).map(|(i, l)| l[0] == l[1] && data.normals[i] != [0.0; 3]).collect()
    };
    let first = n.min(INTERIOR_PROBE);
    let mut all = interior(0..first);
    let probe_share = all.iter().filter(|&&b| b).count() as f64 / first as f64;
    if probe_share < INTERIOR_MIN_SHARE {
        return (probe_share, 0);
    }
    all.extend(interior(first..n));
    let dropped = all.iter().filter(|&&b| b).count();
    let share = dropped as f64 / n as f64;
    if n - dropped < n / 100 {
        return (share, 0);
    }
    let kept = |v: &[[f64; 3]]| v.iter().zip(&all).filter(|(_, &b)| !b).map(|(p, _)| *p).collect();
    data.surface = kept(&data.surface);
    data.normals = kept(&data.normals);
    (share, dropped)
}
