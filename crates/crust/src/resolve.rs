//! Making a rounded crust valid: merging what the output's floats cannot keep apart.
//!
//! The crust is exact for its sites, but its vertices are circumcentres rounded to f64
//! (and, when written, mapped to the mesh frame and rounded again, to f32 for glTF).
//! Where sites are nearly degenerate — nearly cospherical, as mirrored pairs across a
//! smooth surface are by construction — one Voronoi vertex of high degree splits into a
//! cluster of distinct vertices some 1e-17…1e-14 apart, joined by tiny Voronoi edges and
//! sliver faces. Rounding moves those vertices by a sizeable fraction of the cluster, so
//! triangles meeting in the cluster can cross, fold or collapse. Exactly cospherical
//! tetrahedra are already merged by the exact in-sphere test, but nearly cospherical ones
//! are not, and their rounded positions no longer describe a valid surface.
//!
//! [`resolve`] is a snap-rounding-style repair driven by the exact checker: around the
//! triangles the checker finds at fault, it merges the vertices joined by crust edges no
//! longer than a distance that starts at 0 (vertices rounded onto each other) and grows by
//! factors of 4 from one unit in the last place of the output, and rebuilds the polygons
//! (a polygon through merged vertices splits into simple loops; loops of fewer than three
//! vertices, the collapsed sliver faces, vanish). Every half-edge stays paired with an
//! opposite one, so the rebuilt crust is closed and oriented by construction; the manifold
//! step and the exact checker decide the rest. Merging is the degenerate limit of the
//! diagram: a collapsed cluster is the one Voronoi vertex of high degree that exactly
//! cospherical sites would have, and no site moves.
//!
//! Where the output must have a distinct position for every vertex (a file: every reader
//! welds coincident positions), copies of one position — split vertices where inside
//! cells touch along an edge or at a point — are moved apart by a few units in the last
//! place, each into its own solid (against its area-weighted normal), and checked again.

use std::collections::HashMap;

use mesh_io::TriMesh;

use crate::check::{find_defects, CrustCheck};
use crate::error::CrustError;
use crate::manifold::{self, Built};

type V = [f64; 3];

/// How the output stores positions.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Target {
    /// Round a coordinate to the output's precision (the identity for f64).
    pub round: fn(f64) -> f64,
    /// Relative spacing of the output's floats: 2⁻⁵² for f64, 2⁻²³ for f32.
    pub epsilon: f64,
    /// Whether distinct vertices need distinct positions (a file: readers weld).
    pub distinct_positions: bool,
    /// The largest merge distance tried, relative to the largest extent of the mesh.
    pub max_merge: f64,
}

/// A valid mesh and what it took.
pub(crate) struct Outcome {
    pub built: Built,
    pub check: CrustCheck,
    /// Polygon vertices merged into others.
    pub num_merged: usize,
    /// The merge distance (max-norm, output units) of the successful attempt; 0 when
    /// nothing was merged or only coincident vertices were.
    pub merge_distance: f64,
    /// Vertices moved apart from a coincident copy.
    pub num_separated: usize,
    /// Components and genus before the repair, when merging vertices at most
    /// [`TOPOLOGY_SLACK_UNITS`] apart changed them (a handle or a gap thinner than a few
    /// units in the last place of the output closed).
    pub topology_before: Option<(usize, i64)>,
}

/// Merging vertices this many units in the last place apart (or fewer) may change the
/// topology: a handle or a gap that thin cannot be kept apart by the output's floats (it
/// is what rounding does to it), and refusing to write the crust would be worse. Merges
/// over longer edges that change the topology are refused: they would collapse features.
pub(crate) const TOPOLOGY_SLACK_UNITS: f64 = 4.0;

/// Why an attempt failed: a message, and the polygon vertices at fault (`None`: all).
pub(crate) struct Failure {
    pub message: String,
    pub bad: Option<Vec<u32>>,
    /// Components and genus of the mesh built, when it was closed, manifold and oriented.
    pub topology: Option<(usize, i64)>,
}

/// Displacements tried, in units in the last place, for separating coincident copies.
const SEPARATION_STEPS: [f64; 5] = [4.0, 16.0, 64.0, 256.0, 1024.0];

/// Build and check the polygons as they are.
pub(crate) fn attempt(
    polygons: &[Vec<u32>],
    positions: &[V],
    target: &Target,
) -> Result<(Built, CrustCheck, usize), Failure> {
    let mut built = manifold::build(polygons, positions).map_err(|e| Failure {
        message: e.message,
        bad: Some(e.vertices),
        topology: None,
    })?;
    for (p, &m) in built.mesh.positions.iter_mut().zip(&built.computed) {
        if m {
            *p = p.map(target.round);
        }
    }
    let defects_to_failure = |built: &Built, d: crate::check::Defects| Failure {
        bad: (!d.triangles.is_empty()).then(|| {
            d.triangles
                .iter()
                .flat_map(|&t| built.mesh.triangles[t as usize])
                .map(|v| built.source[v as usize])
                .collect()
        }),
        message: d.message,
        topology: d.topology,
    };
    let groups = if target.distinct_positions { coincident_groups(&built.mesh) } else { Vec::new() };
    if groups.is_empty() {
        return match find_defects(&built.mesh, false) {
            Ok(check) => Ok((built, check, 0)),
            Err(d) => Err(defects_to_failure(&built, d)),
        };
    }
    let original = built.mesh.positions.clone();
    let mut first_failure = None;
    let num_separated = groups.iter().map(Vec::len).sum();
    for k in SEPARATION_STEPS {
        built.mesh.positions.clone_from(&original);
        separate(&mut built.mesh, &groups, k, target);
        if !coincident_groups(&built.mesh).is_empty() {
            continue;
        }
        match find_defects(&built.mesh, false) {
            Ok(check) => return Ok((built, check, num_separated)),
            Err(d) => {
                if first_failure.is_none() {
                    first_failure = Some(d);
                }
            }
        }
    }
    built.mesh.positions = original;
    let mut failure = match first_failure {
        Some(d) => defects_to_failure(&built, d),
        None => Failure {
            message: "coincident vertices could not be moved apart".into(),
            bad: Some(Vec::new()),
            topology: None,
        },
    };
    if let Some(bad) = &mut failure.bad {
        bad.extend(groups.iter().flatten().map(|&v| built.source[v as usize]));
    }
    failure.message = format!(
        "{} vertices share a position with another (readers weld them) and moving them apart failed: {}",
        num_separated, failure.message
    );
    Err(failure)
}

/// Merge and rebuild until the exact checker accepts the mesh, starting from a failed
/// attempt on the polygons as they are (`first`).
///
/// - `polygons`: oriented simple polygons as ids into `positions`;
/// - `positions`: #P×3, already in the output's precision.
///
/// # Errors
/// [`CrustError::Internal`] naming the last defect when no merge distance up to
/// `target.max_merge` of the mesh's largest extent gives a valid mesh, or when the only
/// valid meshes found change the number of components or the genus of `first` by merging
/// vertices more than [`TOPOLOGY_SLACK_UNITS`] apart (then the merging would have collapsed
/// real features, not rounding noise).
pub(crate) fn resolve(
    polygons: &[Vec<u32>],
    positions: &[V],
    target: &Target,
    first: Failure,
    expect: Option<(usize, i64)>,
) -> Result<Outcome, CrustError> {
    let expect = expect.or(first.topology);
    let n = positions.len();
    let max_abs = positions.iter().flatten().fold(0.0f64, |m, &c| m.max(c.abs()));
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let diagonal = (0..3).map(|k| (hi[k] - lo[k]).max(0.0)).fold(0.0f64, f64::max);
    let unit = (max_abs * target.epsilon).max(f64::MIN_POSITIVE);
    // Up to `max_merge` of the extent, and at least 16 units in the last place (a mesh far
    // from the origin compared with its size has few of them across it).
    let cap = (diagonal * target.max_merge).max(16.0 * unit);
    let mut levels = vec![0.0];
    let mut t = unit;
    while t <= cap {
        levels.push(t);
        t *= 4.0;
    }
    // Crust edges with their max-norm lengths.
    let mut edges: Vec<(u32, u32, f64)> = Vec::new();
    for p in polygons {
        for i in 0..p.len() {
            let (a, b) = (p[i], p[(i + 1) % p.len()]);
            if a < b {
                let (pa, pb) = (positions[a as usize], positions[b as usize]);
                edges.push((a, b, (0..3).map(|k| (pa[k] - pb[k]).abs()).fold(0.0, f64::max)));
            }
        }
    }
    edges.sort_unstable_by(|x, y| x.2.total_cmp(&y.2));
    let mut bad = vec![false; n];
    let mark = |bad: &mut Vec<bool>, f: &Failure| match &f.bad {
        Some(vs) => vs.iter().for_each(|&v| bad[v as usize] = true),
        None => bad.iter_mut().for_each(|b| *b = true),
    };
    mark(&mut bad, &first);
    let mut last_message = first.message;
    let mut tried: Vec<u32> = (0..n as u32).collect();
    for &tol in &levels {
        loop {
            let rep = representatives(n, &edges, tol, &bad, positions);
            if rep == tried {
                break;
            }
            let loops = split_loops(polygons, &rep);
            match attempt(&loops, positions, target) {
                Ok((built, check, num_separated)) => {
                    let got = (check.report.num_components, check.report.genus);
                    let mut topology_before = None;
                    if let Some((c, g)) = expect.filter(|&(c, g)| got != (c, Some(g))) {
                        if tol <= TOPOLOGY_SLACK_UNITS * unit {
                            topology_before = Some((c, g));
                        } else {
                            return Err(CrustError::Internal(format!(
                                "rounding the crust's vertices breaks it, and the merging that repairs it \
                                 (vertices up to {tol:.3e} apart) changes its topology from {c} component(s) of \
                                 genus {g} to {} of genus {:?}",
                                got.0, got.1
                            )));
                        }
                    }
                    let num_merged = rep.iter().enumerate().filter(|&(v, &r)| r as usize != v).count();
                    return Ok(Outcome {
                        built,
                        check,
                        num_merged,
                        merge_distance: tol,
                        num_separated,
                        topology_before,
                    });
                }
                Err(f) => {
                    mark(&mut bad, &f);
                    last_message = f.message;
                }
            }
            tried = rep;
        }
    }
    Err(CrustError::Internal(format!(
        "rounding the crust's vertices breaks it and merging vertices up to {cap:.3e} apart did not repair it ({last_message})"
    )))
}

/// Union-find with path halving.
fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let p = parent[parent[x as usize] as usize];
        parent[x as usize] = p;
        x = p;
    }
    x
}

/// Per vertex, the vertex it merges into: components of the edges no longer than `tol`
/// that hold a bad vertex collapse onto the member nearest their mean (ties: the smaller
/// id); every other vertex stays itself.
fn representatives(n: usize, edges: &[(u32, u32, f64)], tol: f64, bad: &[bool], positions: &[V]) -> Vec<u32> {
    let mut parent: Vec<u32> = (0..n as u32).collect();
    for &(a, b, len) in edges {
        if len > tol {
            break;
        }
        let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
        if ra != rb {
            parent[ra.max(rb) as usize] = ra.min(rb);
        }
    }
    let mut members: HashMap<u32, Vec<u32>> = HashMap::new();
    for v in 0..n as u32 {
        let r = find(&mut parent, v);
        if r != v {
            members.entry(r).or_default().push(v);
        }
    }
    let mut rep: Vec<u32> = (0..n as u32).collect();
    for (root, mut ms) in members {
        ms.push(root);
        if !ms.iter().any(|&v| bad[v as usize]) {
            continue;
        }
        ms.sort_unstable();
        let mean = [0, 1, 2].map(|k| ms.iter().map(|&v| positions[v as usize][k]).sum::<f64>() / ms.len() as f64);
        let dist = |v: u32| {
            let p = positions[v as usize];
            (0..3).map(|k| (p[k] - mean[k]).powi(2)).sum::<f64>()
        };
        let best = ms.iter().copied().min_by(|&a, &b| dist(a).total_cmp(&dist(b)).then(a.cmp(&b))).unwrap_or(root);
        for &v in &ms {
            rep[v as usize] = best;
        }
    }
    rep
}

/// The polygons with every vertex replaced by its representative, each split into simple
/// loops at repeated vertices (a closed walk is a union of simple cycles, so every
/// half-edge keeps its place); loops of fewer than three vertices are dropped, each of
/// them a collapsed face whose half-edges cancel in pairs.
pub(crate) fn split_loops(polygons: &[Vec<u32>], rep: &[u32]) -> Vec<Vec<u32>> {
    let mut out = Vec::with_capacity(polygons.len());
    let mut stack: Vec<u32> = Vec::new();
    for p in polygons {
        stack.clear();
        for &v in p {
            let v = rep[v as usize];
            if let Some(i) = stack.iter().position(|&w| w == v) {
                let cycle = stack.split_off(i + 1);
                if cycle.len() >= 2 {
                    let mut l = Vec::with_capacity(cycle.len() + 1);
                    l.push(v);
                    l.extend_from_slice(&cycle);
                    out.push(l);
                }
            } else {
                stack.push(v);
            }
        }
        if stack.len() >= 3 {
            out.push(stack.clone());
        }
    }
    out
}

/// Groups of mesh vertices that share a position (−0.0 and 0.0 alike), each of two or
/// more ids, in order of first appearance.
pub(crate) fn coincident_groups(mesh: &TriMesh) -> Vec<Vec<u32>> {
    let key = |p: &V| p.map(|c| if c == 0.0 { 0u64 } else { c.to_bits() });
    let mut first: HashMap<[u64; 3], usize> = HashMap::with_capacity(mesh.positions.len());
    let mut groups: Vec<Vec<u32>> = Vec::new();
    let mut group_of_first: HashMap<usize, usize> = HashMap::new();
    for (v, p) in mesh.positions.iter().enumerate() {
        match first.get(&key(p)) {
            None => {
                first.insert(key(p), v);
            }
            Some(&f) => {
                let g = *group_of_first.entry(f).or_insert_with(|| {
                    groups.push(vec![f as u32]);
                    groups.len() - 1
                });
                groups[g].push(v as u32);
            }
        }
    }
    groups
}

/// Move every vertex of every group by `k` units in the last place of the output, against
/// its area-weighted normal (into its own solid), rounded to the output's precision.
fn separate(mesh: &mut TriMesh, groups: &[Vec<u32>], k: f64, target: &Target) {
    let mut normal: HashMap<u32, V> = HashMap::new();
    for g in groups {
        for &v in g {
            normal.insert(v, [0.0; 3]);
        }
    }
    for t in &mesh.triangles {
        if !t.iter().any(|v| normal.contains_key(v)) {
            continue;
        }
        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
        let (u, w) = ([0, 1, 2].map(|i| b[i] - a[i]), [0, 1, 2].map(|i| c[i] - a[i]));
        let n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]];
        for v in t {
            if let Some(s) = normal.get_mut(v) {
                for i in 0..3 {
                    s[i] += n[i];
                }
            }
        }
    }
    for g in groups {
        for &v in g {
            let p = mesh.positions[v as usize];
            let n = normal[&v];
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if !(len > 0.0) {
                continue;
            }
            let ulp = (p.iter().fold(0.0f64, |m, c| m.max(c.abs())) * target.epsilon).max(f64::MIN_POSITIVE);
            let step = k * ulp / len;
            mesh.positions[v as usize] = [0, 1, 2].map(|i| {
                let x = (target.round)(p[i] - step * n[i]);
                if x == 0.0 {
                    0.0
                } else {
                    x
                }
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn loops_split_at_repeated_vertices_and_collapse() {
        // 0 1 2 3 with 3 merged into 1: the walk 0 1 2 1 splits into [1 2] (dropped) and [0 1].
        let rep = [0, 1, 2, 1, 4, 5];
        assert!(split_loops(&[vec![0, 1, 2, 3]], &rep).is_empty());
        // A pentagon with 2 merged into 1 keeps 0 1 3 4.
        let rep = [0, 1, 1, 3, 4];
        assert_eq!(split_loops(&[vec![0, 1, 2, 3, 4]], &rep), vec![vec![0, 1, 3, 4]]);
        // A figure eight: 0 1 2 0' 3 4 with 0' = 0 gives two triangles.
        let rep = [0, 1, 2, 0, 3, 4];
        let l = split_loops(&[vec![0, 1, 2, 3, 4, 5]], &rep);
        assert_eq!(l, vec![vec![0, 1, 2], vec![0, 3, 4]]);
    }
}
