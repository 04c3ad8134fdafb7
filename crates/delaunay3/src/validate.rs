//! [`Delaunay3::validate`]: a complete check of the invariants.

use crate::build::INFINITE;
use crate::error::ValidationError;
use crate::predicates::{in_conflict_finite, in_conflict_infinite};
use crate::triangulation::Delaunay3;
use rayon::prelude::*;

/// Facet opposite vertex `i` as indices, oriented with vertex `i` on its positive side.
pub(crate) const FACET: [[usize; 3]; 4] = [[1, 3, 2], [0, 2, 3], [0, 3, 1], [0, 1, 2]];

macro_rules! fail {
    ($($arg:tt)*) => { return Err(ValidationError(format!($($arg)*))) };
}

impl Delaunay3 {
    /// Check every invariant exactly; `Ok(())` means this is a valid Delaunay
    /// tetrahedralization of the input (under the crate's symbolic perturbation).
    ///
    /// Checks, in order:
    /// 1. shapes: finite tetrahedra first, the infinite vertex only at index 3, vertex ids
    ///    in range and distinct within a tetrahedron, every vertex used, the two vertex
    ///    maps inverse to each other;
    /// 2. adjacency: every neighbour link is symmetric, and the two tetrahedra induce
    ///    opposite orientations on the shared facet (same three vertices);
    /// 3. exact positive orientation of every finite tetrahedron;
    /// 4. exact local Delaunay property, with the same perturbation as construction,
    ///    across every facet (finite–finite: in-sphere; infinite ones: the hull is
    ///    locally convex and coplanar hull facets are locally Delaunay in their plane);
    /// 5. hull: the facets of the infinite tetrahedra form one connected closed surface
    ///    of Euler characteristic 2 (V − E + F = 2);
    /// 6. the whole complex is connected.
    ///
    /// Together these imply a Delaunay tetrahedralization: (2)+(3)+(5) make the finite
    /// tetrahedra an oriented pseudomanifold whose boundary is an embedded convex surface,
    /// so the simplicial map has degree one and the tetrahedra tile the convex hull
    /// without overlap; local Delaunay then implies global Delaunay (Delaunay 1934;
    /// Edelsbrunner 2001, "Geometry and Topology for Mesh Generation", §2).
    ///
    /// # Complexity
    /// O(T) predicates, T the number of tetrahedra, in parallel (rayon).
    ///
    /// # Errors
    /// The first broken invariant, naming the tetrahedron, face and vertices.
    pub fn validate(&self) -> Result<(), ValidationError> {
        let nt = self.cells.len();
        let nv = self.points.len();
        if self.num_finite > nt {
            fail!("array lengths disagree");
        }
        if self.num_finite == 0 {
            fail!("no finite tetrahedron");
        }
        // 1. Shapes.
        let mut used = vec![false; nv];
        for (t, v) in self.tets().enumerate() {
            let finite = t < self.num_finite;
            for k in 0..4 {
                if v[k] == INFINITE {
                    if finite || k != 3 {
                        fail!("tet {t} {v:?}: infinite vertex at index {k} (finite part ends at {})", self.num_finite);
                    }
                    continue;
                }
                if v[k] as usize >= nv {
                    fail!("tet {t} {v:?}: vertex id out of range ({nv} vertices)");
                }
                used[v[k] as usize] = true;
                for l in 0..k {
                    if v[l] == v[k] {
                        fail!("tet {t} {v:?}: repeated vertex");
                    }
                }
            }
            if !finite && v[3] != INFINITE {
                fail!("tet {t} {v:?}: in the infinite part but finite");
            }
        }
        if let Some(v) = used.iter().position(|&u| !u) {
            fail!("vertex {v} is in no tetrahedron");
        }
        for (v, &i) in self.input_of_vertex.iter().enumerate() {
            if self.vertex_of_input.get(i as usize) != Some(&(v as u32)) {
                fail!("vertex {v} represented by input {i}, which maps elsewhere");
            }
        }
        if self.vertex_of_input.iter().any(|&v| v as usize >= nv) {
            fail!("an input maps to a vertex id out of range");
        }

        // 2–4, per tetrahedron, in parallel (read-only).
        (0..nt).into_par_iter().with_min_len(1 << 12).try_for_each(|t| self.check_tet(t))?;

        // 5. Hull surface.
        let num_hull = nt - self.num_finite;
        if num_hull < 4 || num_hull & 1 != 0 {
            fail!("{num_hull} hull facets cannot form a closed triangulated surface");
        }
        let mut on_hull = vec![false; nv];
        for v in self.infinite_tets() {
            for &u in &v[..3] {
                on_hull[u as usize] = true;
            }
        }
        let hull_vertices = on_hull.iter().filter(|&&h| h).count();
        let euler = hull_vertices as i64 - (3 * num_hull / 2) as i64 + num_hull as i64;
        if euler != 2 {
            fail!("hull surface has Euler characteristic {euler} (V={hull_vertices}, F={num_hull}), not 2");
        }
        let reached = self.flood(self.num_finite, true);
        if reached != num_hull {
            fail!("hull surface is not connected ({reached} of {num_hull} facets reachable)");
        }

        // 6. Connectivity.
        let reached = self.flood(0, false);
        if reached != nt {
            fail!("complex is not connected ({reached} of {nt} tetrahedra reachable)");
        }
        Ok(())
    }

    /// Checks 2 (adjacency), 3 (orientation) and 4 (local Delaunay) for tetrahedron `t`.
    fn check_tet(&self, t: usize) -> Result<(), ValidationError> {
        let nt = self.cells.len();
        let v = self.cells[t].v;
        // 2. Adjacency.
        #[allow(clippy::needless_range_loop)] // i indexes FACET and the cell
        for i in 0..4 {
            let e = self.cells[t].n[i];
            let (n, j) = ((e >> 2) as usize, (e & 3) as usize);
            if n >= nt {
                fail!("tet {t} face {i}: neighbour {n} out of range");
            }
            if self.cells[n].n[j] != (t * 4 + i) as u32 {
                fail!("tet {t} face {i} -> tet {n} face {j}, which points back to {}", self.cells[n].n[j]);
            }
            let f = FACET[i].map(|k| v[k]);
            let g = FACET[j].map(|k| self.cells[n].v[k]);
            // g must be f reversed, up to rotation.
            let r = [f[0], f[2], f[1]];
            if !(g == r || g == [r[1], r[2], r[0]] || g == [r[2], r[0], r[1]]) {
                fail!("tet {t} face {i} facet {f:?} and tet {n} face {j} facet {g:?} do not match with opposite orientations");
            }
        }
        // 3. Orientation.
        if t < self.num_finite && self.orient_v(v) <= 0 {
            fail!("finite tet {t} {v:?} is not positively oriented");
        }
        // 4. Local Delaunay.
        let p = |v: u32| &self.points[v as usize];
        for i in 0..4 {
            let e = self.cells[t].n[i];
            let (n, j) = ((e >> 2) as usize, (e & 3) as usize);
            let apex = self.cells[n].v[j];
            if apex == INFINITE {
                continue; // ∞ is outside every finite circumsphere
            }
            let conflict = if v[3] == INFINITE {
                in_conflict_infinite(p(v[0]), p(v[1]), p(v[2]), p(apex), self.far)
            } else {
                if n < self.num_finite && n < t {
                    continue; // symmetric: checked from the other side
                }
                in_conflict_finite([p(v[0]), p(v[1]), p(v[2]), p(v[3])], p(apex))
            };
            if conflict {
                fail!("facet {i} of tet {t} {v:?} is not locally Delaunay: apex {apex} of tet {n} {:?} is inside its (perturbed) circumsphere", self.cells[n].v);
            }
        }
        Ok(())
    }

    /// Number of tetrahedra reachable from `start` through facets; with `hull_only`,
    /// only through the faces 0..3 of infinite tetrahedra.
    fn flood(&self, start: usize, hull_only: bool) -> usize {
        let mut seen = vec![false; self.cells.len()];
        let mut stack = vec![start];
        seen[start] = true;
        let mut count = 0;
        while let Some(t) = stack.pop() {
            count += 1;
            let faces = if hull_only { 0..3 } else { 0..4 };
            for i in faces {
                let n = (self.cells[t].n[i] >> 2) as usize;
                if !seen[n] {
                    seen[n] = true;
                    stack.push(n);
                }
            }
        }
        count
    }
}

#[cfg(test)]
mod tests {
    use crate::Delaunay3;

    fn sample() -> Delaunay3 {
        let mut s = 99u64;
        let mut next = move || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let pts: Vec<[f64; 3]> = (0..200).map(|_| [next(), next(), next()]).collect();
        let dt = Delaunay3::new(&pts).unwrap();
        dt.validate().unwrap();
        dt
    }

    #[test]
    fn detects_flipped_orientation() {
        let mut dt = sample();
        dt.cells[3].v.swap(0, 1);
        assert!(dt.validate().is_err());
    }

    #[test]
    fn detects_broken_adjacency() {
        let mut dt = sample();
        let other = dt.cells[7].n[1];
        dt.cells[3].n[2] = other;
        assert!(dt.validate().is_err());
    }

    #[test]
    fn detects_non_delaunay_facet() {
        // Move one vertex to the circumcentre-ish middle of a far tetrahedron: the
        // combinatorics stay, the geometry stops being Delaunay (or oriented).
        let mut dt = sample();
        let far_tet = dt.cells[dt.num_finite / 2].v;
        let v = dt.cells[0].v[0];
        let c = [0, 1, 2].map(|k| far_tet.iter().map(|&u| dt.points[u as usize][k]).sum::<f64>() / 4.0);
        dt.points[v as usize] = [c[0] + 1e-3, c[1], c[2]];
        let e = dt.validate().unwrap_err();
        assert!(e.0.contains("Delaunay") || e.0.contains("oriented"), "{e}");
    }

    #[test]
    fn detects_unused_vertex_and_bad_maps() {
        let mut dt = sample();
        dt.input_of_vertex[5] = dt.input_of_vertex[6];
        assert!(dt.validate().is_err());
    }
}
