//! The cube's numbering: corners, faces, local edges, and the masks relating them.
//!
//! Corners: bit 0 → +axis 0, bit 1 → +axis 1, bit 2 → +axis 2. Local edges: the axis
//! times 4 plus the other two bits of the lower corner ([`edge_of`]).

/// Cube corners: bit 0 → +axis 0, bit 1 → +axis 1, bit 2 → +axis 2. Faces as corner
/// cycles counter-clockwise seen from outside the cube.
pub(super) const FACES: [[usize; 4]; 6] =
    [[0, 4, 6, 2], [1, 3, 7, 5], [0, 1, 5, 4], [2, 6, 7, 3], [0, 2, 3, 1], [4, 5, 7, 6]];

/// Local edge index of the cube edge between corners `a` and `b` (adjacent): the axis
/// (bit that differs) times 4 plus the other two bits of the lower corner.
pub(super) const fn edge_of(a: usize, b: usize) -> usize {
    let lo = if a < b { a } else { b };
    let axis = (a ^ b).trailing_zeros() as usize;
    let rest = match axis {
        0 => lo >> 1,
        1 => (lo & 1) | ((lo >> 2) << 1),
        _ => lo & 3,
    };
    axis * 4 + rest
}

/// Lower corner of local edge `e`.
pub(super) const fn edge_lower_corner(e: usize) -> usize {
    let (axis, rest) = (e / 4, e % 4);
    match axis {
        0 => rest << 1,
        1 => (rest & 1) | ((rest >> 1) << 2),
        _ => rest,
    }
}

/// Bit `f` set when local edge `e` lies on face `f` of [`FACES`].
pub(super) const fn edge_face_mask(e: usize) -> u8 {
    let mut m = 0u8;
    let mut f = 0;
    while f < 6 {
        let mut q = 0;
        while q < 4 {
            if edge_of(FACES[f][q], FACES[f][(q + 1) % 4]) == e {
                m |= 1 << f;
            }
            q += 1;
        }
        f += 1;
    }
    m
}

/// Bit `f` set when corner `c` lies on face `f`.
pub(super) const fn corner_face_mask(c: usize) -> u8 {
    let mut m = 0u8;
    let mut f = 0;
    while f < 6 {
        let mut q = 0;
        while q < 4 {
            if FACES[f][q] == c {
                m |= 1 << f;
            }
            q += 1;
        }
        f += 1;
    }
    m
}

/// The 12 cube edges as corner pairs.
pub(super) const CUBE_EDGES: [(usize, usize); 12] =
    [(0, 1), (2, 3), (4, 5), (6, 7), (0, 2), (1, 3), (4, 6), (5, 7), (0, 4), (1, 5), (2, 6), (3, 7)];
