//! Consistent orientation within each connected piece of a mesh.
//!
//! The workspace's solid is the generalized winding number's |w| ≥ 0.5, and w depends on
//! the triangles' orientation: crossing a face changes it by +1 or −1 by the face's
//! direction. Where some triangles of a closed body are flipped against their neighbours
//! (STL exports, hand-edited CAD), w no longer jumps by 1 across the body's surface, so
//! part of the body reads as outside and a region outside the body as inside (on the
//! quality benchmark's `multibody`, a box with 6 of its 12 triangles flipped: a wedge of
//! "solid" grows out of one face and the fit reproduces it faithfully, Hausdorff 12.7% of
//! the diagonal; with the box consistently oriented, 0.05%).
//!
//! [`orient_consistently`] repairs exactly that and nothing else: triangles are joined
//! across manifold edges (edges with exactly two triangles), each such piece is oriented
//! by breadth-first search so that every shared edge is used once in each direction, and
//! of the two consistent orientations the one that keeps more of the piece's area as
//! given is chosen. A piece that is already consistent is left as it is, whatever its
//! direction (an inward-facing body, a cavity's wall): only disagreement between
//! neighbours is repaired. A piece that cannot be oriented (a Möbius strip) is left as it
//! is, and so are triangles joined only through non-manifold or boundary edges.
//!
//! Why by hand: trimesh's `fix_winding` does the same on the Python side, but the Rust
//! mesh crates here (tobj, gltf) only read meshes; the traversal is fifty lines.

use std::collections::HashMap;

use crate::TriMesh;

/// What [`orient_consistently`] changed.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct Reorientation {
    /// Triangles whose orientation was reversed.
    pub flipped_triangles: usize,
    /// Pieces (joined across manifold edges) with at least one flipped triangle.
    pub pieces_changed: usize,
    /// Pieces that cannot be oriented consistently (left as they are).
    pub non_orientable_pieces: usize,
}

/// `mesh` with every piece joined across manifold edges consistently oriented (module doc),
/// and what changed. Positions are untouched; a flipped triangle [a, b, c] becomes
/// [a, c, b].
pub fn orient_consistently(mesh: &TriMesh) -> (TriMesh, Reorientation) {
    let tris = &mesh.triangles;
    // Undirected edge → the triangles using it, with whether each runs it low → high.
    let mut edges: HashMap<(u32, u32), Vec<(u32, bool)>> = HashMap::with_capacity(tris.len() * 3 / 2);
    for (f, t) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if a != b {
                edges.entry((a.min(b), a.max(b))).or_default().push((f as u32, a < b));
            }
        }
    }
    // Neighbours across manifold edges: (other triangle, whether the two run the edge the
    // same way, i.e. disagree).
    let mut adjacency: Vec<Vec<(u32, bool)>> = vec![Vec::new(); tris.len()];
    for uses in edges.values() {
        if let [(f, df), (g, dg)] = uses[..] {
            if f != g {
                adjacency[f as usize].push((g, df == dg));
                adjacency[g as usize].push((f, df == dg));
            }
        }
    }
    let area = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
        let (u, w) = ([0, 1, 2].map(|k| b[k] - a[k]), [0, 1, 2].map(|k| c[k] - a[k]));
        let n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]];
        (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt()
    };
    let mut flip: Vec<Option<bool>> = vec![None; tris.len()];
    let mut report = Reorientation::default();
    let mut out = mesh.triangles.clone();
    let mut queue = std::collections::VecDeque::new();
    for seed in 0..tris.len() {
        if flip[seed].is_some() {
            continue;
        }
        flip[seed] = Some(false);
        queue.push_back(seed as u32);
        let mut piece = Vec::new();
        let mut orientable = true;
        while let Some(f) = queue.pop_front() {
            piece.push(f);
            let ff = flip[f as usize].unwrap_or(false);
            for &(g, disagree) in &adjacency[f as usize] {
                // Neighbours that disagree as given need opposite flips, and vice versa.
                let want = ff ^ disagree;
                match flip[g as usize] {
                    None => {
                        flip[g as usize] = Some(want);
                        queue.push_back(g);
                    }
                    Some(have) if have != want => orientable = false,
                    Some(_) => {}
                }
            }
        }
        if !orientable {
            report.non_orientable_pieces += 1;
            continue;
        }
        let (mut kept, mut flipped) = (0.0, 0.0);
        for &f in &piece {
            let a = area(&tris[f as usize]);
            if flip[f as usize] == Some(true) {
                flipped += a;
            } else {
                kept += a;
            }
        }
        // Of the two consistent orientations, the one that changes less area.
        let invert = flipped > kept;
        let mut changed = 0;
        for &f in &piece {
            if flip[f as usize] == Some(!invert) {
                let t = &mut out[f as usize];
                t.swap(1, 2);
                changed += 1;
            }
        }
        if changed > 0 {
            report.flipped_triangles += changed;
            report.pieces_changed += 1;
        }
    }
    (TriMesh { positions: mesh.positions.clone(), triangles: out }, report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes::{cuboid, icosphere};
    use crate::TopologyReport;

    fn flipped(m: &TriMesh, which: impl Fn(usize) -> bool) -> TriMesh {
        let triangles =
            m.triangles.iter().enumerate().map(|(i, t)| if which(i) { [t[0], t[2], t[1]] } else { *t }).collect();
        TriMesh { positions: m.positions.clone(), triangles }
    }

    #[test]
    fn consistent_meshes_are_left_alone_in_either_direction() {
        let s = icosphere(2);
        for m in [s.clone(), flipped(&s, |_| true)] {
            let (o, r) = orient_consistently(&m);
            assert_eq!(r, Reorientation::default());
            assert_eq!(o, m);
        }
    }

    #[test]
    fn a_minority_of_flipped_triangles_is_turned_back() {
        let s = icosphere(2);
        let n = s.triangles.len();
        let m = flipped(&s, |i| i % 7 == 3);
        assert!(!TopologyReport::of(&m).is_orientation_consistent);
        let (o, r) = orient_consistently(&m);
        assert_eq!(o, s);
        assert_eq!(r.flipped_triangles, (0..n).filter(|i| i % 7 == 3).count());
        assert_eq!(r.pieces_changed, 1);
        assert!(TopologyReport::of(&o).is_orientation_consistent);
    }

    #[test]
    fn each_piece_keeps_its_own_majority() {
        // An outward box with 2 triangles flipped and an inward box (a cavity's wall, say)
        // with 3 flipped: each goes back to what most of its area says.
        let a = cuboid([0.0; 3], [1.0; 3]);
        let b = flipped(&cuboid([2.0; 3], [3.0; 3]), |_| true);
        let n = a.positions.len() as u32;
        let both = TriMesh {
            positions: a.positions.iter().chain(&b.positions).copied().collect(),
            triangles: a.triangles.iter().copied().chain(b.triangles.iter().map(|t| t.map(|v| v + n))).collect(),
        };
        let broken = flipped(&both, |i| [0, 5, 12, 13, 20].contains(&i));
        let (o, r) = orient_consistently(&broken);
        assert_eq!(o, both);
        assert_eq!((r.flipped_triangles, r.pieces_changed, r.non_orientable_pieces), (5, 2, 0));
        let t = TopologyReport::of(&o);
        assert!(t.is_orientation_consistent);
        assert!(t.signed_volume.abs() < 1e-12, "outward 1 and inward 1: {}", t.signed_volume);
    }

    #[test]
    fn a_moebius_strip_is_left_as_it_is() {
        // A band of 8 quads whose ends are joined with a half twist.
        let n = 8;
        let mut positions = Vec::new();
        for i in 0..n {
            let a = i as f64 / n as f64 * std::f64::consts::TAU;
            let h = a / 2.0;
            for s in [-1.0, 1.0] {
                let r = 1.0 + 0.3 * s * h.cos();
                positions.push([r * a.cos(), r * a.sin(), 0.3 * s * h.sin()]);
            }
        }
        let mut triangles = Vec::new();
        for i in 0..n as u32 {
            let (a, b) = (2 * i, 2 * i + 1);
            let (c, d) = if i + 1 < n as u32 { (2 * i + 2, 2 * i + 3) } else { (1, 0) };
            triangles.push([a, c, b]);
            triangles.push([b, c, d]);
        }
        let m = TriMesh { positions, triangles };
        let (o, r) = orient_consistently(&m);
        assert_eq!(o, m);
        assert_eq!(r.non_orientable_pieces, 1);
    }
}
