//! Triangles of a cell's polygons outside the classic table: a fan per polygon (from a
//! corner whose diagonals leave the cell's faces, else around a new centroid vertex), and a
//! tube (a ring of new vertices and two strips) joining two polygons.

/// A tube joining two polygons whose oriented edges it keeps as its boundary: a ring of
/// new vertices halfway between `c1` and the cell's middle (so that no tube edge lies in a
/// cell face), a strip from `c1` to the ring, a strip from the ring to `c2`.
pub(super) fn tube_triangles(
    c1: &[(u32, u8)],
    c2: &[(u32, u8)],
    out: &mut Vec<[u32; 3]>,
    positions: &mut Vec<[f64; 3]>,
) {
    let centroid = |c: &[(u32, u8)], positions: &Vec<[f64; 3]>| {
        let mut m = [0.0; 3];
        for &(v, _) in c {
            for k in 0..3 {
                m[k] += positions[v as usize][k] / c.len() as f64;
            }
        }
        m
    };
    let (m1, m2) = (centroid(c1, positions), centroid(c2, positions));
    let mid: [f64; 3] = std::array::from_fn(|k| 0.5 * (m1[k] + m2[k]));
    let a: Vec<u32> = c1.iter().map(|c| c.0).collect();
    let ring: Vec<u32> = a
        .iter()
        .map(|&v| {
            let p = positions[v as usize];
            positions.push(std::array::from_fn(|k| 0.5 * (p[k] + mid[k])));
            (positions.len() - 1) as u32
        })
        .collect();
    // Strip c1[i] → c1[i + 1] → ring[i + 1] → ring[i].
    let n = a.len();
    for i in 0..n {
        let j = (i + 1) % n;
        out.push([a[i], a[j], ring[j]]);
        out.push([a[i], ring[j], ring[i]]);
    }
    let b: Vec<u32> = c2.iter().map(|c| c.0).collect();
    zipper(&ring, &b, out, positions);
}

/// Triangles of the annulus whose oriented boundary is `a` and `b`, both as given (they
/// must run in opposite senses around the annulus; at least 3 vertices each): `a` walked
/// forwards, `b` backwards, from their closest pair of vertices, the two advancing evenly
/// (so that no diagonal is used twice).
fn zipper(a: &[u32], b: &[u32], out: &mut Vec<[u32; 3]>, positions: &[[f64; 3]]) {
    let (na, nb) = (a.len(), b.len());
    let dist = |x: u32, y: u32| {
        let (p, q) = (positions[x as usize], positions[y as usize]);
        (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)
    };
    let mut best = (f64::INFINITY, 0, 0);
    for (i, &ai) in a.iter().enumerate() {
        for (j, &bj) in b.iter().enumerate() {
            let d = dist(ai, bj);
            if d < best.0 {
                best = (d, i, j);
            }
        }
    }
    let (_, mut i, mut j) = best;
    let (mut left_a, mut left_b) = (na, nb);
    while left_a + left_b > 0 {
        let (ai, ai1) = (a[i % na], a[(i + 1) % na]);
        let (bj, bj1) = (b[j % nb], b[(j + nb - 1) % nb]);
        let (done_a, done_b) = (na - left_a, nb - left_b);
        let advance_a = left_b == 0 || (left_a > 0 && (2 * done_a + 1) * nb < (2 * done_b + 1) * na);
        if advance_a {
            out.push([ai, ai1, bj]);
            i = (i + 1) % na;
            left_a -= 1;
        } else {
            out.push([bj1, bj, ai]);
            j = (j + nb - 1) % nb;
            left_b -= 1;
        }
    }
}

/// Triangles of one polygon (vertex, faces of the cell it lies on) oriented as given: a fan
/// from the first corner whose diagonals all leave the cell's faces (a diagonal between two
/// points of one face would lie in that face, where the neighbouring cell may put the same
/// segment: a non-manifold edge), else a fan around a new vertex at the polygon's centroid,
/// inside the cell.
pub(super) fn triangulate(cycle: &[(u32, u8)], out: &mut Vec<[u32; 3]>, positions: &mut Vec<[f64; 3]>) {
    out.clear();
    let n = cycle.len();
    if n < 3 {
        return;
    }
    'start: for s in 0..n {
        let apex = cycle[s];
        for t in 2..n - 1 {
            if apex.1 & cycle[(s + t) % n].1 != 0 {
                continue 'start;
            }
        }
        for t in 1..n - 1 {
            out.push([apex.0, cycle[(s + t) % n].0, cycle[(s + t + 1) % n].0]);
        }
        return;
    }
    let mut c = [0.0; 3];
    for &(v, _) in cycle {
        for k in 0..3 {
            c[k] += positions[v as usize][k];
        }
    }
    positions.push(c.map(|x| x / n as f64));
    let centre = (positions.len() - 1) as u32;
    for t in 0..n {
        out.push([centre, cycle[t].0, cycle[(t + 1) % n].0]);
    }
}
