//! The crust in the plane, for the MNIST autoencoder: the Voronoi edges between inside and
//! outside sites, read from an exact 2D Delaunay triangulation.
//!
//! It is the same rule as the 3D crust ([`crate::Crust`]): a Voronoi facet belongs to the
//! crust when it is dual to a Delaunay edge whose two sites carry different labels. In 3D
//! the facet is a polygon around a Delaunay edge of delaunay3's tetrahedralization; here
//! it is a segment between the circumcentres of the two triangles beside a Delaunay edge
//! of spade's triangulation (a ray where the edge is on the convex hull). The
//! triangulation — which sites are Voronoi neighbours — is exact (spade uses Shewchuk's
//! adaptive orientation and in-circle predicates through the `robust` crate, as delaunay3
//! does); the circumcentres are rounded f64, which only matters for drawing.
//!
//! In the plane every triangle has either no bichromatic edge or exactly two, so the crust
//! is a set of closed loops and of chains that end in rays; [`PlanarDiagram::crust`] joins
//! them in order and clips them to the requested box.
//!
//! Why not a shared code path with the 3D crust: delaunay3 is a 3D tetrahedralization and
//! the 3D extraction's work is making a watertight manifold triangle mesh out of Voronoi
//! polygons, which has no counterpart for segments. What is shared is the rule above and
//! the sites/labels conventions (duplicate sites share one Delaunay vertex).

use spade::{DelaunayTriangulation, HasPosition, Point2, Triangulation};

use crate::CrustError;

/// A Voronoi edge clipped to the box: the two sites it separates and its end points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanarEdge {
    /// The two sites (input indices) whose cells meet along the edge.
    pub sites: [u32; 2],
    /// The clipped segment.
    pub segment: [[f64; 2]; 2],
}

/// The planar Voronoi diagram of labelled sites, clipped to a box.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlanarDiagram {
    /// Delaunay edges as input site indices (a < b), each once.
    pub delaunay_edges: Vec<(u32, u32)>,
    /// Every Voronoi edge that meets the box, clipped to it.
    pub edges: Vec<PlanarEdge>,
    /// The crust: polylines through the Voronoi edges between differently labelled sites,
    /// clipped to the box. A closed loop repeats its first point at the end.
    pub crust: Vec<Vec<[f64; 2]>>,
}

struct Site {
    p: Point2<f64>,
}

impl HasPosition for Site {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.p
    }
}

/// An end of a Voronoi edge before clipping.
#[derive(Clone, Copy, Debug, PartialEq)]
enum End {
    /// The circumcentre of an inner triangle (its face index).
    Face(usize, [f64; 2]),
    /// Unbounded: a ray from the other end in this direction.
    Infinite([f64; 2]),
}

/// The Voronoi diagram of `sites` with `labels`, clipped to the box `lo`..`hi`.
///
/// # Errors
/// [`CrustError::Planar`] for a label count that differs from the site count, fewer than two
/// sites, a non-finite coordinate, or a coordinate spade cannot take (|x| > ~1e150).
pub fn planar_diagram(
    sites: &[[f64; 2]],
    labels: &[bool],
    lo: [f64; 2],
    hi: [f64; 2],
) -> Result<PlanarDiagram, CrustError> {
    if labels.len() != sites.len() {
        return Err(CrustError::Planar(format!("{} sites but {} labels", sites.len(), labels.len())));
    }
    if sites.len() < 2 {
        return Err(CrustError::Planar(format!("{} sites: a planar diagram needs at least 2", sites.len())));
    }
    if let Some(i) = sites.iter().position(|p| !(p[0].is_finite() && p[1].is_finite())) {
        return Err(CrustError::Planar(format!("site {i} has a non-finite coordinate {:?}", sites[i])));
    }
    let mut dt: DelaunayTriangulation<Site> = DelaunayTriangulation::new();
    // Input index of each Delaunay vertex (the first site inserted at that position).
    let mut input_of_vertex: Vec<u32> = Vec::with_capacity(sites.len());
    for (i, p) in sites.iter().enumerate() {
        let h = dt
            .insert(Site { p: Point2::new(p[0], p[1]) })
            .map_err(|e| CrustError::Planar(format!("site {i} at {p:?}: {e:?}")))?;
        if h.index() == input_of_vertex.len() {
            input_of_vertex.push(i as u32);
        }
    }
    let mut out = PlanarDiagram::default();
    if dt.num_vertices() < 2 {
        return Ok(out);
    }
    // Voronoi edge of every Delaunay edge: (sites, two ends).
    let mut raw: Vec<([u32; 2], End, End)> = Vec::new();
    for e in dt.undirected_edges() {
        let d = e.as_directed();
        let (va, vb) = (d.from(), d.to());
        let (a, b) = (input_of_vertex[va.fix().index()], input_of_vertex[vb.fix().index()]);
        let (pa, pb) = (va.position(), vb.position());
        let dir = [pb.y - pa.y, -(pb.x - pa.x)]; // right of a → b
        let end = |face: spade::handles::FaceHandle<'_, spade::handles::PossiblyOuterTag, Site, (), (), ()>,
                   outward: [f64; 2]| match face.as_inner() {
            Some(f) => {
                let c = f.circumcenter();
                End::Face(f.fix().index(), [c.x, c.y])
            }
            None => End::Infinite(outward),
        };
        // The left face's circumcentre, and the right face's; an outer face on the right
        // sends the edge off to the right, and one on the left to the left.
        let left = end(d.face(), [-dir[0], -dir[1]]);
        let right = end(d.rev().face(), dir);
        out.delaunay_edges.push((a.min(b), a.max(b)));
        raw.push(([a, b], left, right));
    }
    for &(s, l, r) in &raw {
        if let Some(seg) = clip_edge(l, r, pa_mid(sites, s), lo, hi) {
            out.edges.push(PlanarEdge { sites: s, segment: seg });
        }
    }
    out.crust = crust_chains(&raw, sites, labels, lo, hi);
    Ok(out)
}

/// The midpoint of the two sites (a point on their bisector, for edges with two
/// unbounded ends).
fn pa_mid(sites: &[[f64; 2]], s: [u32; 2]) -> [f64; 2] {
    let (a, b) = (sites[s[0] as usize], sites[s[1] as usize]);
    [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]
}

/// A far point along a ray (the box is in the unit range for every caller; 1e6 keeps the
/// clip well conditioned).
const FAR: f64 = 1e6;

fn unit(v: [f64; 2]) -> [f64; 2] {
    let l = v[0].hypot(v[1]);
    if l > 0.0 {
        [v[0] / l, v[1] / l]
    } else {
        [0.0, 0.0]
    }
}

/// The segment of a Voronoi edge with ends `l`, `r` (before clipping).
fn edge_segment(l: End, r: End, mid: [f64; 2]) -> [[f64; 2]; 2] {
    match (l, r) {
        (End::Face(_, a), End::Face(_, b)) => [a, b],
        (End::Face(_, a), End::Infinite(d)) => {
            let u = unit(d);
            [a, [a[0] + FAR * u[0], a[1] + FAR * u[1]]]
        }
        (End::Infinite(d), End::Face(_, b)) => {
            let u = unit(d);
            [[b[0] + FAR * u[0], b[1] + FAR * u[1]], b]
        }
        (End::Infinite(d1), End::Infinite(d2)) => {
            let (u1, u2) = (unit(d1), unit(d2));
            [[mid[0] + FAR * u1[0], mid[1] + FAR * u1[1]], [mid[0] + FAR * u2[0], mid[1] + FAR * u2[1]]]
        }
    }
}

fn clip_edge(l: End, r: End, mid: [f64; 2], lo: [f64; 2], hi: [f64; 2]) -> Option<[[f64; 2]; 2]> {
    let [a, b] = edge_segment(l, r, mid);
    clip_segment(a, b, lo, hi)
}

/// Liang–Barsky clipping of the segment a–b to the box.
pub fn clip_segment(a: [f64; 2], b: [f64; 2], lo: [f64; 2], hi: [f64; 2]) -> Option<[[f64; 2]; 2]> {
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    let d = [b[0] - a[0], b[1] - a[1]];
    for c in 0..2 {
        for (p, q) in [(-d[c], a[c] - lo[c]), (d[c], hi[c] - a[c])] {
            if p == 0.0 {
                if q < 0.0 {
                    return None;
                }
            } else {
                let t = q / p;
                if p < 0.0 {
                    t0 = t0.max(t);
                } else {
                    t1 = t1.min(t);
                }
            }
        }
    }
    (t0 <= t1).then(|| [[a[0] + t0 * d[0], a[1] + t0 * d[1]], [a[0] + t1 * d[0], a[1] + t1 * d[1]]])
}

/// Joins the bichromatic Voronoi edges into chains through shared circumcentres, then
/// clips each chain to the box (a chain leaving and re-entering the box becomes several).
fn crust_chains(
    raw: &[([u32; 2], End, End)],
    sites: &[[f64; 2]],
    labels: &[bool],
    lo: [f64; 2],
    hi: [f64; 2],
) -> Vec<Vec<[f64; 2]>> {
    let crust: Vec<usize> =
        (0..raw.len()).filter(|&i| labels[raw[i].0[0] as usize] != labels[raw[i].0[1] as usize]).collect();
    // Edges at each inner face (0 or 2 in a valid triangulation).
    let mut at_face: std::collections::HashMap<usize, Vec<usize>> = std::collections::HashMap::new();
    for &i in &crust {
        for end in [raw[i].1, raw[i].2] {
            if let End::Face(f, _) = end {
                at_face.entry(f).or_default().push(i);
            }
        }
    }
    let mut used = vec![false; raw.len()];
    let mut chains: Vec<Vec<[f64; 2]>> = Vec::new();
    // Walk from edge `start`, entered at its end `reversed ? right : left`, through shared
    // circumcentres until the chain closes or ends in a ray.
    let walk = |start: usize, reversed: bool, used: &mut Vec<bool>| -> Vec<[f64; 2]> {
        let (s, l, r) = raw[start];
        let seg = edge_segment(l, r, pa_mid(sites, s));
        let (mut pts, mut tail) = if reversed { (vec![seg[1], seg[0]], l) } else { (vec![seg[0], seg[1]], r) };
        used[start] = true;
        let mut cur = start;
        while let End::Face(f, _) = tail {
            let Some(next) = at_face.get(&f).and_then(|v| v.iter().copied().find(|&j| j != cur && !used[j])) else {
                break;
            };
            used[next] = true;
            let (s2, l2, r2) = raw[next];
            let seg2 = edge_segment(l2, r2, pa_mid(sites, s2));
            // Continue from the end that is this face.
            let (far, far_end) = if matches!(l2, End::Face(g, _) if g == f) { (seg2[1], r2) } else { (seg2[0], l2) };
            pts.push(far);
            cur = next;
            tail = far_end;
        }
        pts
    };
    // Chains with an unbounded end first, started from that end; the rest are loops.
    for &i in &crust {
        if !used[i] {
            match (raw[i].1, raw[i].2) {
                (End::Infinite(_), _) => chains.push(walk(i, false, &mut used)),
                (_, End::Infinite(_)) => chains.push(walk(i, true, &mut used)),
                _ => {}
            }
        }
    }
    for &i in &crust {
        if !used[i] {
            chains.push(walk(i, false, &mut used));
        }
    }
    let mut out = Vec::new();
    for chain in chains {
        let mut run: Vec<[f64; 2]> = Vec::new();
        for w in chain.windows(2) {
            match clip_segment(w[0], w[1], lo, hi) {
                Some([a, b]) => {
                    if run.last() != Some(&a) {
                        if run.len() >= 2 {
                            out.push(std::mem::take(&mut run));
                        }
                        run.clear();
                        run.push(a);
                    }
                    run.push(b);
                }
                None => {
                    if run.len() >= 2 {
                        out.push(std::mem::take(&mut run));
                    }
                    run.clear();
                }
            }
        }
        if run.len() >= 2 {
            out.push(run);
        }
    }
    out
}

/// The Voronoi cell of site `i` clipped to the box, as a convex polygon (counter-clockwise
/// in a y-up frame), from the site's Delaunay neighbours `neighbors`: the box cut by the
/// bisector half-plane of each neighbour (Sutherland–Hodgman). For drawing.
pub fn cell_polygon(
    sites: &[[f64; 2]],
    i: usize,
    neighbors: impl IntoIterator<Item = u32>,
    lo: [f64; 2],
    hi: [f64; 2],
) -> Vec<[f64; 2]> {
    let p = sites[i];
    let mut poly = vec![lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]];
    for j in neighbors {
        let q = sites[j as usize];
        if q == p {
            continue;
        }
        // Keep x with (x − m)·(q − p) ≤ 0.
        let n = [q[0] - p[0], q[1] - p[1]];
        let m = [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])];
        let side = |x: [f64; 2]| (x[0] - m[0]) * n[0] + (x[1] - m[1]) * n[1];
        let mut next = Vec::with_capacity(poly.len() + 1);
        for k in 0..poly.len() {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            let (sa, sb) = (side(a), side(b));
            if sa <= 0.0 {
                next.push(a);
            }
            if (sa < 0.0 && sb > 0.0) || (sa > 0.0 && sb < 0.0) {
                let t = sa / (sa - sb);
                next.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
            }
        }
        poly = next;
        if poly.is_empty() {
            break;
        }
    }
    poly
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_square_of_inside_sites_in_a_ring_of_outside_sites_gives_one_closed_loop() {
        let mut sites = Vec::new();
        let mut labels = Vec::new();
        for i in 0..6 {
            for j in 0..6 {
                sites.push([0.1 + 0.16 * i as f64 + 0.01 * j as f64, 0.1 + 0.16 * j as f64]);
                labels.push((1..5).contains(&i) && (1..5).contains(&j));
            }
        }
        let d = planar_diagram(&sites, &labels, [0.0; 2], [1.0; 2]).unwrap();
        assert_eq!(d.crust.len(), 1, "{:?}", d.crust);
        let c = &d.crust[0];
        assert_eq!(c.first(), c.last(), "closed");
        // Every crust point is on the bisector of an inside and an outside site: equidistant
        // from its nearest inside and nearest outside site.
        for x in c {
            let near = |want: bool| {
                sites
                    .iter()
                    .zip(&labels)
                    .filter(|(_, &l)| l == want)
                    .map(|(p, _)| (p[0] - x[0]).hypot(p[1] - x[1]))
                    .fold(f64::INFINITY, f64::min)
            };
            assert!((near(true) - near(false)).abs() < 1e-9, "{x:?}");
        }
        // Cells tile the box.
        let area: f64 = (0..sites.len())
            .map(|i| {
                let nb: Vec<u32> = d
                    .delaunay_edges
                    .iter()
                    .filter_map(|&(a, b)| {
                        if a as usize == i {
                            Some(b)
                        } else if b as usize == i {
                            Some(a)
                        } else {
                            None
                        }
                    })
                    .collect();
                let poly = cell_polygon(&sites, i, nb, [0.0; 2], [1.0; 2]);
                (0..poly.len())
                    .map(|k| {
                        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
                        a[0] * b[1] - a[1] * b[0]
                    })
                    .sum::<f64>()
                    / 2.0
            })
            .sum();
        assert!((area - 1.0).abs() < 1e-9, "{area}");
    }

    #[test]
    fn collinear_and_duplicate_sites_and_bad_input() {
        let sites = [[0.2, 0.5], [0.4, 0.5], [0.6, 0.5], [0.4, 0.5]];
        let d = planar_diagram(&sites, &[false, true, false, true], [0.0; 2], [1.0; 2]).unwrap();
        // Two vertical lines, x = 0.3 and x = 0.5, each a full-height chain.
        assert_eq!(d.crust.len(), 2);
        for c in &d.crust {
            assert!((c[0][0] - c[c.len() - 1][0]).abs() < 1e-12);
            assert!((c[0][1] - c[c.len() - 1][1]).abs() > 0.999);
        }
        assert!(planar_diagram(&sites, &[true], [0.0; 2], [1.0; 2]).is_err());
        assert!(planar_diagram(&[[0.0, f64::NAN], [1.0, 1.0]], &[true, false], [0.0; 2], [1.0; 2]).is_err());
        assert!(planar_diagram(&[[0.0, 0.0]], &[true], [0.0; 2], [1.0; 2]).is_err());
    }
}
