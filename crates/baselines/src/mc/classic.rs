//! The classic 256-case table's triangulation (Lorensen & Cline 1987, as listed by Paul
//! Bourke and used by scikit-image), mapped onto this module's corner and edge numbering.

use super::cube::edge_of;

/// Corner of this module (bit 0 → axis 0, bit 1 → axis 1, bit 2 → axis 2) for each corner of
/// the classic table's numbering, (x, y, z) = 0 (0,0,0), 1 (1,0,0), 2 (1,1,0), 3 (0,1,0), then
/// the same at z = 1. skimage puts the table's x along array axis 2 and z along axis 0 (found
/// by trying the 48 symmetries of the cube against skimage on all 254 cases; only this one
/// gives its triangles in every case).
const CLASSIC_CORNER: [usize; 8] = [0, 4, 6, 2, 1, 5, 7, 3];

/// This module's local edge for each edge of the classic table's numbering: 0–3 the cycle of
/// corners 0-1-2-3, 4–7 the cycle 4-5-6-7, 8–11 the edges from corner c to c + 4.
const CLASSIC_EDGE: [usize; 12] = {
    let mut out = [0usize; 12];
    let mut e = 0;
    while e < 12 {
        let (p, q) = if e < 4 {
            (e, (e + 1) % 4)
        } else if e < 8 {
            (e, 4 + (e - 3) % 4)
        } else {
            (e - 8, e - 4)
        };
        out[e] = edge_of(CLASSIC_CORNER[p], CLASSIC_CORNER[q]);
        e += 1;
    }
    out
};

/// The classic 256-case table's triangles for a cell whose above corners are `mask` (this
/// module's corner bits), as local vertices (`local_vertex[e]` for local edge `e`), oriented
/// like this module's polygons for [`Inside::Above`](super::Inside::Above). Returns false (and leaves `out` alone)
/// if a table edge has no vertex, which cannot happen when the cell's crossed edges are the
/// table's.
///
/// The table is `marching_cubes::tables::TRI_TABLE` (Paul Bourke's listing of the Lorensen–
/// Cline table, the one scikit-image's `method="lorensen"` uses and whose triangulations
/// its `"lewiner"` tables share in the unambiguous cases): it is data that fixes which
/// diagonals split each polygon, and using it makes the triangles, not only the polygons,
/// those of skimage. It is indexed, as skimage does, by the corners above the level (so an
/// ambiguous face separates its above corners), and with skimage's axis order its triangles
/// already turn the way this module's polygons do (the unit test below checks both).
pub(super) fn classic_triangles(mask: u32, local_vertex: &[u32; 12], out: &mut Vec<[u32; 3]>) -> bool {
    let mut index = 0usize;
    for (b, &c) in CLASSIC_CORNER.iter().enumerate() {
        if mask & (1 << c) != 0 {
            index |= 1 << b;
        }
    }
    let row = &marching_cubes::tables::TRI_TABLE[index];
    let start = out.len();
    for t in row.chunks_exact(3) {
        if t[0] < 0 {
            break;
        }
        let v = |k: usize| usize::try_from(t[k]).ok().and_then(|e| CLASSIC_EDGE.get(e)).map(|&e| local_vertex[e]);
        match (v(0), v(1), v(2)) {
            (Some(a), Some(b), Some(c)) if a != u32::MAX && b != u32::MAX && c != u32::MAX => out.push([a, b, c]),
            _ => {
                out.truncate(start);
                return false;
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mc::ambiguity::face_segments;
    use crate::mc::cube::edge_face_mask;
    use crate::mc::Ambiguity;
    use std::collections::BTreeSet;

    /// For all 256 cases: the classic table's triangles (vertex = local edge) have exactly the
    /// directed boundary of the polygons `face_segments` builds with every face separating its
    /// above corners, so the table agrees with this module's faces and orientation, and every
    /// interior diagonal is used by exactly two triangles and lies off the cube's faces.
    #[test]
    fn classic_table_triangulates_the_separate_above_polygons() {
        let ids: [u32; 12] = std::array::from_fn(|e| e as u32);
        for mask in 1u32..255 {
            let v: [f64; 8] = std::array::from_fn(|c| if mask & (1 << c) != 0 { 1.0 } else { -1.0 });
            let (succ, joined, _) = face_segments(&v, mask, Ambiguity::SeparateAbove);
            assert_eq!(joined, 0);
            let polygon: BTreeSet<(u32, u32)> =
                (0..12).filter(|&e| succ[e] != usize::MAX).map(|e| (e as u32, succ[e] as u32)).collect();
            let mut local = [u32::MAX; 12];
            for e in 0..12 {
                if succ[e] != usize::MAX {
                    local[e] = ids[e];
                }
            }
            let mut tris = Vec::new();
            assert!(classic_triangles(mask, &local, &mut tris), "case {mask:#010b}: table edge without crossing");
            let directed: Vec<(u32, u32)> =
                tris.iter().flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])]).collect();
            let set: BTreeSet<(u32, u32)> = directed.iter().copied().collect();
            assert_eq!(set.len(), directed.len(), "case {mask:#010b}: a directed edge used twice");
            let boundary: BTreeSet<(u32, u32)> = set.iter().copied().filter(|&(a, b)| !set.contains(&(b, a))).collect();
            assert_eq!(boundary, polygon, "case {mask:#010b}");
            let faces = |e: u32| edge_face_mask(e as usize);
            for &(a, b) in set.difference(&boundary) {
                assert_eq!(faces(a) & faces(b), 0, "case {mask:#010b}: diagonal {a}-{b} lies in a cube face");
            }
        }
    }
}
