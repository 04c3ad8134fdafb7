//! TEMPORARY (refactor check): prints every certified/libigl result bit for bit.
use mesh_io::shapes::{box_with_hole, icosphere, torus};
use mesh_io::TriMesh;
use metrics::{CertifiedOptions, HausdorffInterval};
#[allow(unused_imports)]
use metrics::MetricsError;

#[allow(dead_code)]
#[path = "/tmp/vf_fp/orig/crates_metrics_src_hausdorff.rs"]
mod orig;

fn same(name: &str, new: &HausdorffInterval, old: &orig::HausdorffInterval) {
    let n = format!("{:?}", HausdorffInterval { seconds: 0.0, ..new.clone() });
    let o = format!("{:?}", orig::HausdorffInterval { seconds: 0.0, ..old.clone() });
    if n != o { println!("MISMATCH {name}\n new {n}\n old {o}"); } else { println!("same {name}: [{:?}, {:?}] q {}", new.lo, new.hi, new.queries); }
}

fn xf(m: &TriMesh, s: f64, t: [f64; 3]) -> TriMesh {
    TriMesh { positions: m.positions.iter().map(|p| [0, 1, 2].map(|k| p[k] * s + t[k])).collect(), triangles: m.triangles.clone() }
}
fn wobble(m: &TriMesh, amp: f64) -> TriMesh {
    TriMesh {
        positions: m.positions.iter().enumerate().map(|(i, p)| {
            let f = 1.0 + amp * ((i as f64 * 0.37).sin());
            p.map(|x| x * f)
        }).collect(),
        triangles: m.triangles.clone(),
    }
}

use std::cmp::Ordering;
use std::collections::BinaryHeap;
use occupancy::{MeshOracle, Workspace};
use rayon::prelude::*;
const CENTER: [f64; 3] = [0.5, 0.5, 0.5];
const RADIUS: f64 = 0.35;
pub fn sphere_hausdorff(mesh: &TriMesh, oracle: &MeshOracle, tol: f64) -> (f64, f64) {
    use occupancy::distance::closest_point_triangle::closest_point_triangle;
    let norm =
        |a: [f64; 3], b: [f64; 3]| ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
    let h1 = mesh
        .triangles
        .par_iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            let out = [a, b, c].iter().map(|&v| norm(v, CENTER) - RADIUS).fold(f64::NEG_INFINITY, f64::max);
            let inw = RADIUS - norm(closest_point_triangle(CENTER, a, b, c), CENTER);
            out.max(inw)
        })
        .reduce(|| f64::NEG_INFINITY, f64::max);

    #[derive(PartialEq)]
    struct Patch {
        ub: f64,
        corners: [[f64; 3]; 3],
    }
    impl Eq for Patch {}
    impl PartialOrd for Patch {
        fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
            Some(self.cmp(o))
        }
    }
    impl Ord for Patch {
        fn cmp(&self, o: &Self) -> Ordering {
            self.ub.total_cmp(&o.ub)
        }
    }
    let normalize = |v: [f64; 3]| {
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        v.map(|x| x / l)
    };
    let on_sphere = |u: [f64; 3]| [0, 1, 2].map(|k| CENTER[k] + RADIUS * u[k]);
    // Evaluates a patch: (lower bound, upper bound).
    let eval = |corners: &[[f64; 3]; 3], ws: &mut Workspace| {
        let s = normalize([0, 1, 2].map(|k| corners[0][k] + corners[1][k] + corners[2][k]));
        let d = oracle.closest_point(on_sphere(s), ws).squared_distance.sqrt();
        let r = corners.iter().map(|&a| norm(s, a)).fold(0.0, f64::max) * RADIUS;
        (d, d + r)
    };
    // The starting patches: the icosahedron's faces (unit vectors, counter-clockwise).
    let icosahedron = mesh_io::shapes::icosphere(0);
    let mut ws = Workspace::new();
    let mut lo2: f64 = 0.0;
    let mut heap = BinaryHeap::new();
    for f in &icosahedron.triangles {
        let corners = f.map(|i| icosahedron.positions[i as usize]);
        let (lo, ub) = eval(&corners, &mut ws);
        lo2 = lo2.max(lo);
        heap.push(Patch { ub, corners });
    }
    let mut evaluations = 0usize;
    while let Some(top) = heap.peek() {
        if top.ub <= lo2 + tol || evaluations > 20_000_000 {
            break;
        }
        let Some(p) = heap.pop() else { break };
        let [a, b, c] = p.corners;
        let (ab, bc, ca) = (
            normalize([0, 1, 2].map(|k| a[k] + b[k])),
            normalize([0, 1, 2].map(|k| b[k] + c[k])),
            normalize([0, 1, 2].map(|k| c[k] + a[k])),
        );
        for corners in [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]] {
            let (lo, ub) = eval(&corners, &mut ws);
            evaluations += 1;
            lo2 = lo2.max(lo);
            if ub > lo2 + tol {
                heap.push(Patch { ub, corners });
            }
        }
    }
    let hi2 = heap.peek().map_or(lo2, |p| p.ub.max(lo2));
    let margin = 64.0 * f64::EPSILON * (1.0 + RADIUS + 1.0);
    let lo = h1.max(lo2) - margin;
    let hi = h1.max(hi2) + margin;
    (lo.max(0.0), hi)
}


fn sphere_cases(bunny: &TriMesh) {
    let sphere = mesh_io::shapes::Sphere { center: CENTER, radius: RADIUS };
    let mut meshes: Vec<(String, TriMesh)> = Vec::new();
    for k in 0..5 { meshes.push((format!("ico{k}"), xf(&icosphere(k), RADIUS, CENTER))); }
    meshes.push(("ico3-small".into(), xf(&icosphere(3), RADIUS * 0.97, CENTER)));
    meshes.push(("ico3-wob".into(), xf(&wobble(&icosphere(3), 0.02), RADIUS, CENTER)));
    meshes.push(("ico2-off".into(), xf(&icosphere(2), 0.3, [0.52, 0.49, 0.5])));
    meshes.push(("torus".into(), xf(&torus(1.0, 0.35, 32, 16), 0.3, CENTER)));
    meshes.push(("box".into(), xf(&box_with_hole(1.0, 0.3), 0.3, CENTER)));
    let (lo, hi) = bunny.bounding_box();
    let s = 0.8 / (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
    meshes.push(("bunny".into(), xf(bunny, s, [0.1 - lo[0] * s, 0.1 - lo[1] * s, 0.1 - lo[2] * s])));
    for (name, m) in &meshes {
        for tol in [1e-6 * 3f64.sqrt(), 1e-3, 0.0 + 1e-9] {
            let oracle = MeshOracle::from_mesh(m, &occupancy::Config::default()).unwrap();
            let old = sphere_hausdorff(m, &oracle, tol);
            let new = metrics::hausdorff_sphere_certified(m, &sphere, tol).unwrap();
            let ok = old.0.to_bits() == new.lo.to_bits() && old.1.to_bits() == new.hi.to_bits();
            println!("{} sphere {name} tol {tol:e}: old {old:?} new [{:?}, {:?}] conv {} n {}", if ok { "same" } else { "MISMATCH" }, new.lo, new.hi, new.converged, new.patches_evaluated);
        }
    }
}

fn main() {
    let bunny = mesh_io::read_mesh(std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../assets/bunny.obj"))).unwrap();
    sphere_cases(&bunny);
    let pairs: Vec<(&str, TriMesh, TriMesh)> = vec![
        ("ico3-ico1", icosphere(3), icosphere(1)),
        ("ico4-wob", icosphere(4), wobble(&icosphere(3), 0.01)),
        ("torus", torus(1.0, 0.35, 64, 32), torus(1.02, 0.33, 20, 12)),
        ("box-tor", box_with_hole(1.0, 0.3), torus(1.0, 0.3, 40, 16)),
        ("bunny-shift", bunny.clone(), xf(&bunny, 1.01, [0.001, -0.002, 0.0005])),
        ("bunny-ico", bunny.clone(), xf(&icosphere(2), 0.07, [-0.02, 0.1, 0.0])),
    ];
    for (name, a, b) in &pairs {
        let (l1, l2) = (metrics::hausdorff_libigl(a, b).unwrap(), orig::hausdorff_libigl(a, b).unwrap());
        println!("{} libigl {name}", if l1.to_bits() == l2.to_bits() { "same" } else { "MISMATCH" });
        for (oname, o) in [
            ("default", CertifiedOptions::default()),
            ("allv", CertifiedOptions { all_vertices: true, ..Default::default() }),
            ("tol1e-3", CertifiedOptions { rel_tolerance: 1e-3, ..Default::default() }),
            ("limits", CertifiedOptions { max_depth: 3, max_active_cells: 5000, ..Default::default() }),
        ] {
            let oo = orig::CertifiedOptions { rel_tolerance: o.rel_tolerance, max_depth: o.max_depth, max_active_cells: o.max_active_cells, all_vertices: o.all_vertices };
            same(&format!("{name} {oname} both"), &metrics::hausdorff_certified(a, b, &o).unwrap(), &orig::hausdorff_certified(a, b, &oo).unwrap());
            same(&format!("{name} {oname} ab"), &metrics::directed_hausdorff_certified(a, b, &o).unwrap(), &orig::directed_hausdorff_certified(a, b, &oo).unwrap());
            same(&format!("{name} {oname} ba"), &metrics::directed_hausdorff_certified(b, a, &o).unwrap(), &orig::directed_hausdorff_certified(b, a, &oo).unwrap());
        }
        let e = metrics::evaluate(a, b, &metrics::EvalOptions { iou_samples: Some(0), skip_validity: true, ..Default::default() }).unwrap();
        let (ra, rb) = (orig::DistanceMesh::new(a, "reference").unwrap(), orig::DistanceMesh::new(b, "prediction").unwrap());
        let old = orig::certify(&ra, &rb, orig::Sides::Both, &orig::CertifiedOptions { all_vertices: true, ..Default::default() }).unwrap();
        same(&format!("{name} eval"), &e.hausdorff, &old);
    }
}
