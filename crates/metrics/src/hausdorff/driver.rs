//! The certified branch and bound (see the module doc of [`crate::hausdorff`]): the scale
//! and tolerance, the phases of `passes`, then breadth-first 4-to-1 subdivision of every
//! cell that could still raise the maximum, and the widened interval.

use rayon::prelude::*;
use vf_common::vec3::distance;

use super::cell::{Cell, Engine};
use super::mesh::DistanceMesh;
use super::passes::{pass_a, probe, query_vertices, top_pending, PassB, PassBInput, Pending, VertexDistances, Witness};
use super::{CertifiedOptions, HausdorffInterval, Sides, CHUNK, V3};
use crate::MetricsError;

/// The branch and bound (see the module doc).
pub(crate) fn certify(
    a: &DistanceMesh,
    b: &DistanceMesh,
    sides: Sides,
    opts: &CertifiedOptions,
) -> Result<HausdorffInterval, MetricsError> {
    opts.validate()?;
    let engine = Engine { src: [a, b], tgt: [b, a] };
    let dirs: &[u8] = match sides {
        Sides::Both => &[0, 1],
        Sides::AToB => &[0],
    };
    let scale = Scale::of(a, b, opts.rel_tolerance);
    let tol = scale.tol;

    let vertices = query_vertices(&engine, dirs, opts.all_vertices);
    let libigl = if sides == Sides::Both && vertices.all_exact { Some(vertices.libigl_sq.sqrt()) } else { None };
    let lo0 = vertices.witness.0;
    let first = pass_a(&engine, dirs, &vertices.vert, lo0, tol);
    let mut search = Search {
        lo: lo0,
        witness: vertices.witness,
        directed_witness: vertices.directed_witness,
        active: first.active,
        max_discarded: first.max_discarded,
        queries: vertices.queries,
        cells_evaluated: first.cells_evaluated,
    };
    search.pass_b(&engine, &vertices.vert, &first.pending, tol, opts.max_depth);
    let (depth, converged) = search.refine(&engine, tol, opts);
    Ok(search.finish(&scale, libigl, depth, converged))
}

/// Lengths that fix the tolerance and the rounding margin.
struct Scale {
    /// Diagonal of the bounding box of the referenced vertices of both meshes.
    diagonal: f64,
    /// `128 ε M`, `M` the largest referenced coordinate magnitude (see the module doc).
    rounding_margin: f64,
    /// The tolerance asked for: `rel_tolerance × diagonal`.
    tolerance: f64,
    /// Internal tolerance: the final width includes both margins.
    tol: f64,
}

impl Scale {
    fn of(a: &DistanceMesh, b: &DistanceMesh, rel_tolerance: f64) -> Scale {
        // Bounding box of the referenced vertices of both meshes, largest coordinate.
        let mut lo_box = [f64::INFINITY; 3];
        let mut hi_box = [f64::NEG_INFINITY; 3];
        let mut max_abs = 0.0f64;
        for m in [a, b] {
            for t in &m.mesh.triangles {
                for &v in t {
                    let p = m.mesh.positions[v as usize];
                    for k in 0..3 {
                        lo_box[k] = lo_box[k].min(p[k]);
                        hi_box[k] = hi_box[k].max(p[k]);
                        max_abs = max_abs.max(p[k].abs());
                    }
                }
            }
        }
        let diagonal = distance(lo_box, hi_box);
        let rounding_margin = 128.0 * f64::EPSILON * max_abs;
        let tolerance = rel_tolerance * diagonal;
        let tol = (tolerance - 2.0 * rounding_margin).max(0.0);
        Scale { diagonal, rounding_margin, tolerance, tol }
    }
}

/// What one chunk of a level's cells leaves ([`Search::split_level`]).
struct LevelChunk {
    /// Children above the level's first `lo + tol`, in order.
    kept: Vec<Cell>,
    /// The midpoint distances that raised the chunk's running maximum, in order, with their
    /// points and directions.
    rising: Vec<(f64, V3, u8)>,
    /// The largest midpoint distance of each direction.
    dir_max: [f64; 2],
    /// The largest bound of a child left out.
    max_discarded: f64,
}

/// The state of the search: the lower bound with its witness, the live cells and the
/// largest bound of the settled ones, counters.
struct Search {
    /// Largest distance evaluated at a point of a source surface.
    lo: f64,
    witness: Witness,
    directed_witness: [f64; 2],
    /// Cells whose bound exceeds `lo + tol` (or did against an older `lo`).
    active: Vec<Cell>,
    /// Largest bound of a settled cell or triangle.
    max_discarded: f64,
    queries: u64,
    cells_evaluated: u64,
}

impl Search {
    /// A new exact distance `w` at `x` in direction `dir`.
    fn witnessed(&mut self, w: f64, x: V3, dir: u8) {
        self.directed_witness[dir as usize] = self.directed_witness[dir as usize].max(w);
        if w > self.lo {
            self.lo = w;
            self.witness = (w, x, dir);
        }
    }

    /// Adds the output of a pass B group.
    fn merge(&mut self, out: PassB) {
        self.queries += out.queries;
        for (dir, w) in out.witness.into_iter().enumerate() {
            self.witnessed(w.0, w.1, dir as u8);
        }
        self.active.extend(out.cells);
        self.max_discarded = self.max_discarded.max(out.max_discarded);
    }

    /// Pass B (see `passes`): the TOP_PENDING pending triangles with the largest bounds,
    /// the probe, then the rest against the raised lower bound; finally the cells kept
    /// against an older (smaller) lower bound are settled.
    fn pass_b(&mut self, engine: &Engine, vert: &VertexDistances, pending: &[Pending], tol: f64, max_depth: u32) {
        let input = PassBInput { engine, vert, pending };
        let top = top_pending(pending);
        let mut done = vec![false; pending.len()];
        for &i in &top {
            done[i] = true;
        }
        for out in input.top(&top) {
            self.merge(out);
        }
        for (w, x, dir, nq) in probe(engine, &self.active, self.lo, tol, max_depth) {
            self.queries += nq;
            self.witnessed(w, x, dir);
        }
        let rest: Vec<usize> = (0..pending.len()).filter(|&i| !done[i]).collect();
        for out in input.rest(&rest, self.lo, tol) {
            self.merge(out);
        }
        self.active.retain(|c| {
            let keep = c.ub > self.lo + tol;
            if !keep {
                self.max_discarded = self.max_discarded.max(c.ub);
            }
            keep
        });
    }

    /// Splits the live cells level by level until none is left or a limit is reached;
    /// returns the levels used and whether the search finished.
    fn refine(&mut self, engine: &Engine, tol: f64, opts: &CertifiedOptions) -> (u32, bool) {
        let mut depth = 0u32;
        while !self.active.is_empty() {
            if depth >= opts.max_depth || self.active.len().saturating_mul(4) > opts.max_active_cells {
                return (depth, false);
            }
            depth += 1;
            self.split_level(engine, tol);
        }
        (depth, true)
    }

    /// One level: every live cell split 4-to-1 (in parallel, fixed chunks), the midpoint
    /// distances raise `lo`, and the children above `lo + tol` stay live.
    ///
    /// The same as splitting every cell, then taking the midpoints in order, then keeping
    /// the children above the level's final `lo + tol`, but without holding every child: a
    /// chunk keeps only the children above the level's first `lo + tol` (a superset, since
    /// `lo` only grows) and the midpoints that raise its own running maximum (only those can
    /// raise `lo` when the chunks are taken in order, and the first of the largest wins as
    /// before); the survivors are then cut against the final `lo`. On a print whose crust
    /// runs parallel to the input's faces (8,558 triangles, 7.1 million cells) all the
    /// children of a level held at once took most of the fit's 870 MB peak.
    fn split_level(&mut self, engine: &Engine, tol: f64) {
        let floor = self.lo + tol;
        let chunks: Vec<LevelChunk> = self
            .active
            .par_chunks(CHUNK / 4)
            .map(|chunk| {
                let mut ws = occupancy::Workspace::new();
                let mut out = LevelChunk {
                    kept: Vec::new(),
                    rising: Vec::new(),
                    dir_max: [f64::NEG_INFINITY; 2],
                    max_discarded: f64::NEG_INFINITY,
                };
                for c in chunk {
                    let (children, w, x) = engine.split(c, &mut ws);
                    let d = &mut out.dir_max[c.dir as usize];
                    *d = d.max(w);
                    if out.rising.last().is_none_or(|r: &(f64, V3, u8)| w > r.0) {
                        out.rising.push((w, x, c.dir));
                    }
                    for child in children {
                        if child.ub > floor {
                            out.kept.push(child);
                        } else {
                            out.max_discarded = out.max_discarded.max(child.ub);
                        }
                    }
                }
                out
            })
            .collect();
        self.queries += 3 * self.active.len() as u64;
        self.cells_evaluated += 4 * self.active.len() as u64;
        self.active = Vec::new();
        for c in &chunks {
            for &(w, x, dir) in &c.rising {
                self.witnessed(w, x, dir);
            }
            for (dir, &w) in c.dir_max.iter().enumerate() {
                self.directed_witness[dir] = self.directed_witness[dir].max(w);
            }
            self.max_discarded = self.max_discarded.max(c.max_discarded);
        }
        let mut next = Vec::with_capacity(chunks.iter().map(|c| c.kept.len()).sum());
        for c in chunks {
            for child in c.kept {
                if child.ub > self.lo + tol {
                    next.push(child);
                } else {
                    self.max_discarded = self.max_discarded.max(child.ub);
                }
            }
        }
        self.active = next;
    }

    /// The interval, widened by the rounding margin (`seconds` left at 0).
    fn finish(self, scale: &Scale, libigl: Option<f64>, depth: u32, converged: bool) -> HausdorffInterval {
        let mut hi = self.lo.max(self.max_discarded);
        for c in &self.active {
            hi = hi.max(c.ub);
        }
        HausdorffInterval {
            lo: (self.lo - scale.rounding_margin).max(0.0),
            hi: hi + scale.rounding_margin,
            witness: self.lo,
            witness_point: self.witness.1,
            witness_direction: self.witness.2,
            directed_witness: self.directed_witness,
            libigl,
            tolerance: scale.tolerance,
            diagonal: scale.diagonal,
            rounding_margin: scale.rounding_margin,
            converged,
            depth,
            cells_evaluated: self.cells_evaluated,
            queries: self.queries,
            seconds: 0.0,
        }
    }
}
