//! Ambiguous cells: the face rule (asymptotic decider or a fixed choice) that splits each
//! cube face's crossings into segments, and the exact interior test that decides whether
//! two polygons of a cell are joined by a tube (Nielson & Hamann 1991; Chernyaev 1995;
//! Lewiner et al. 2003).

use super::cube::{edge_of, CUBE_EDGES, FACES};
use super::Ambiguity;

/// The segments the cell's faces contribute (`succ[entry edge] = exit edge`, `usize::MAX`
/// for an edge without crossing), the faces with diagonal above and below corners (bits as
/// in [`FACES`]), and those of them whose above corners were joined. `v`: corner values minus
/// the level; `mask`: above corners.
pub(super) fn face_segments(v: &[f64; 8], mask: u32, ambiguity: Ambiguity) -> ([usize; 12], u8, u8) {
    let above = |c: usize| mask & (1 << c) != 0;
    // Face segments: succ[entry edge] = exit edge.
    let mut succ = [usize::MAX; 12];
    // Ambiguous faces whose above corners are joined.
    let mut joined_faces = 0u8;
    let mut ambiguous_faces = 0u8;
    for (fi, face) in FACES.iter().enumerate() {
        // Crossings in counter-clockwise order; `true` = entering the above region.
        let mut cross = [(0usize, false); 4];
        let mut n = 0;
        for q in 0..4 {
            let (a, b) = (face[q], face[(q + 1) % 4]);
            if above(a) != above(b) {
                cross[n] = (edge_of(a, b), above(b));
                n += 1;
            }
        }
        match n {
            0 => {}
            2 => {
                let (e, x) = if cross[0].1 { (cross[0].0, cross[1].0) } else { (cross[1].0, cross[0].0) };
                succ[e] = x;
            }
            _ => {
                // Rotate so the sequence is entry, exit, entry, exit.
                let r = if cross[0].1 { 0 } else { 1 };
                let (e1, x1, e2, x2) = (cross[r].0, cross[(r + 1) % 4].0, cross[(r + 2) % 4].0, cross[(r + 3) % 4].0);
                let join = match ambiguity {
                    Ambiguity::SeparateAbove => false,
                    Ambiguity::JoinAbove => true,
                    Ambiguity::AsymptoticDecider => {
                        let (a, b, c, d) = (v[face[0]], v[face[1]], v[face[2]], v[face[3]]);
                        // Above pair (a, c) or (b, d); joined iff the saddle is above.
                        if a > 0.0 {
                            a * c - b * d > 0.0
                        } else {
                            b * d - a * c > 0.0
                        }
                    }
                };
                ambiguous_faces |= 1 << fi;
                if join {
                    joined_faces |= 1 << fi;
                    succ[e1] = x2;
                    succ[e2] = x1;
                } else {
                    succ[e1] = x1;
                    succ[e2] = x2;
                }
            }
        }
    }
    (succ, joined_faces, ambiguous_faces)
}

fn find(p: &mut [usize], mut x: usize) -> usize {
    while p[x] != x {
        p[x] = p[p[x]];
        x = p[x];
    }
    x
}

fn union(p: &mut [usize], a: usize, b: usize) {
    let (ra, rb) = (find(p, a), find(p, b));
    if ra != rb {
        p[ra.max(rb)] = ra.min(rb);
    }
}

/// Whether the cell's two polygons bound two regions of one sign (two components of that
/// sign on the cube's surface, one of the other) that the trilinear interpolant connects
/// through the cell's interior. `v`: corner values minus the level; `mask`: above corners;
/// `joined`/`ambiguous`: faces (bits as in [`FACES`]) with two diagonal above corners, and
/// those of them whose above corners the face decision joined.
pub(super) fn joined_inside(v: &[f64; 8], mask: u32, joined: u8, ambiguous: u8) -> bool {
    for above in [true, false] {
        let is_s = |c: usize| (mask & (1 << c) != 0) == above;
        let comp_of = |s: bool| {
            let mut p: [usize; 8] = std::array::from_fn(|i| i);
            for &(a, b) in &CUBE_EDGES {
                if is_s(a) == s && is_s(b) == s {
                    union(&mut p, a, b);
                }
            }
            for (f, face) in FACES.iter().enumerate() {
                if ambiguous & (1 << f) != 0 {
                    // The face's above diagonal is joined iff `joined`, its below one iff not;
                    // the set being built is the above sign iff `s == above`.
                    let join_s = (joined & (1 << f) != 0) == (s == above);
                    if join_s {
                        let (a, c) = if is_s(face[0]) == s { (face[0], face[2]) } else { (face[1], face[3]) };
                        union(&mut p, a, c);
                    }
                }
            }
            let mut roots = [usize::MAX; 8];
            let mut n = 0;
            for c in 0..8 {
                if is_s(c) == s {
                    let r = find(&mut p, c);
                    if !roots[..n].contains(&r) {
                        roots[n] = r;
                        n += 1;
                    }
                }
            }
            (n, p)
        };
        let (n_s, mut p) = comp_of(true);
        let (n_o, _) = comp_of(false);
        if n_s != 2 || n_o != 1 {
            continue;
        }
        // Corner sets of the two components.
        let first = (0..8).find(|&c| is_s(c)).unwrap_or(0);
        let r0 = find(&mut p, first);
        let mut comp = [0u8; 2];
        for c in 0..8 {
            if is_s(c) {
                comp[(find(&mut p, c) != r0) as usize] |= 1 << c;
            }
        }
        // Sign so that the two regions are where g > 0 (below: v ≤ 0, taken as −v > 0).
        let g: [f64; 8] = std::array::from_fn(|c| if above { v[c] } else { -v[c] });
        return connected_in_cube(&g, comp[0], comp[1]);
    }
    false
}

/// Whether corners in `a` and corners in `b` (bit sets, every corner with `g > 0`) lie in one
/// component of `{g > 0}` for the trilinear interpolant `g` of the unit cube.
///
/// Exact sweep along axis 2: each slice is bilinear, and every component of a bilinear
/// slice's positive set contains a positive slice corner; the slice topology changes only
/// where a slice corner crosses 0 (≤ 4 heights) or the slice's saddle does (the roots of the
/// quadratic `A·C − B·D`, ≤ 2). Between those heights components are tracked by the slice
/// corners they contain, and continue across a height through every corner positive on both
/// sides.
fn connected_in_cube(g: &[f64; 8], a: u8, b: u8) -> bool {
    // Slice corner q (bits: axis 0, axis 1) at height t: g[q] + (g[q + 4] − g[q]) t.
    let mut events = [0.0f64; 8];
    let mut ne = 0;
    let mut push = |t: f64, events: &mut [f64; 8]| {
        if t > 0.0 && t < 1.0 && t.is_finite() {
            events[ne] = t;
            ne += 1;
        }
    };
    for q in 0..4 {
        let (g0, g1) = (g[q], g[q + 4]);
        if (g0 > 0.0) != (g1 > 0.0) {
            push(g0 / (g0 - g1), &mut events);
        }
    }
    // det(t) = A C − B D with A = q0, B = q1, C = q3, D = q2 (cyclic order 0, 1, 3, 2).
    let d = |q: usize| g[q + 4] - g[q];
    let c0 = g[0] * g[3] - g[1] * g[2];
    let c1 = g[0] * d(3) + g[3] * d(0) - g[1] * d(2) - g[2] * d(1);
    let c2 = d(0) * d(3) - d(1) * d(2);
    if c2 != 0.0 {
        let disc = c1 * c1 - 4.0 * c2 * c0;
        if disc >= 0.0 {
            let sq = disc.sqrt();
            push((-c1 - sq) / (2.0 * c2), &mut events);
            push((-c1 + sq) / (2.0 * c2), &mut events);
        }
    } else if c1 != 0.0 {
        push(-c0 / c1, &mut events);
    }
    let ev = &mut events[..ne];
    ev.sort_by(f64::total_cmp);
    let mut bounds = [0.0f64; 10];
    bounds[0] = 0.0;
    bounds[1..=ne].copy_from_slice(ev);
    bounds[ne + 1] = 1.0;
    let n_int = ne + 1;
    let mut p: [usize; 40] = std::array::from_fn(|i| i);
    let mut prev_pos = [false; 4];
    for k in 0..n_int {
        let t = 0.5 * (bounds[k] + bounds[k + 1]);
        let s: [f64; 4] = std::array::from_fn(|q| g[q] + (g[q + 4] - g[q]) * t);
        let pos: [bool; 4] = std::array::from_fn(|q| s[q] > 0.0);
        for (x, y) in [(0, 1), (1, 3), (3, 2), (2, 0)] {
            if pos[x] && pos[y] {
                union(&mut p, 4 * k + x, 4 * k + y);
            }
        }
        if pos[0] && pos[3] && !pos[1] && !pos[2] && s[0] * s[3] - s[1] * s[2] > 0.0 {
            union(&mut p, 4 * k, 4 * k + 3);
        }
        if pos[1] && pos[2] && !pos[0] && !pos[3] && s[1] * s[2] - s[0] * s[3] > 0.0 {
            union(&mut p, 4 * k + 1, 4 * k + 2);
        }
        if k > 0 {
            for q in 0..4 {
                if pos[q] && prev_pos[q] {
                    union(&mut p, 4 * (k - 1) + q, 4 * k + q);
                }
            }
        }
        prev_pos = pos;
    }
    // Cube corner c: slice corner c & 3 in the first (c < 4) or last interval.
    let node = |c: usize| if c < 4 { c } else { 4 * (n_int - 1) + (c - 4) };
    for ca in (0..8).filter(|&c| a & (1 << c) != 0) {
        for cb in (0..8).filter(|&c| b & (1 << c) != 0) {
            let (x, y) = (node(ca), node(cb));
            if find(&mut p, x) == find(&mut p, y) {
                return true;
            }
        }
    }
    false
}
