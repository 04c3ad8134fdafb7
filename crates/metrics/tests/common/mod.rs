//! Shared helpers of the metrics tests.
#![allow(dead_code)]

use mesh_io::TriMesh;
use occupancy::distance::closest_point_triangle::closest_point_triangle;

pub fn scaled(m: &TriMesh, s: f64) -> TriMesh {
    TriMesh { positions: m.positions.iter().map(|p| p.map(|x| x * s)).collect(), triangles: m.triangles.clone() }
}

pub fn translated(m: &TriMesh, t: [f64; 3]) -> TriMesh {
    TriMesh {
        positions: m.positions.iter().map(|p| [p[0] + t[0], p[1] + t[1], p[2] + t[2]]).collect(),
        triangles: m.triangles.clone(),
    }
}

/// Brute-force squared distance from `q` to the mesh (same point-triangle arithmetic).
pub fn brute_d2(q: [f64; 3], m: &TriMesh) -> f64 {
    m.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| m.positions[v as usize]);
            let p = closest_point_triangle(q, a, b, c);
            (0..3).map(|k| (q[k] - p[k]).powi(2)).sum::<f64>()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Crude decimation by vertex clustering on a grid of `cells` per axis: every vertex is
/// replaced by the first original vertex of its cell; collapsed triangles are dropped. The
/// kept vertices lie exactly on the original surface, so the original → decimated vertex
/// distances are all that libigl sees, while the surfaces deviate most between vertices.
pub fn cluster_decimate(m: &TriMesh, cells: usize) -> TriMesh {
    let (lo, hi) = m.bounding_box();
    let size = [0, 1, 2].map(|k| (hi[k] - lo[k]) / cells as f64 * (1.0 + 1e-9));
    let mut rep: std::collections::HashMap<[usize; 3], u32> = std::collections::HashMap::new();
    let mut map = vec![0u32; m.positions.len()];
    let mut positions = Vec::new();
    for (i, p) in m.positions.iter().enumerate() {
        let key = [0, 1, 2].map(|k| ((p[k] - lo[k]) / size[k]) as usize);
        let id = *rep.entry(key).or_insert_with(|| {
            positions.push(*p);
            (positions.len() - 1) as u32
        });
        map[i] = id;
    }
    let triangles = m
        .triangles
        .iter()
        .map(|t| t.map(|v| map[v as usize]))
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[2] != t[0])
        .collect();
    TriMesh { positions, triangles }
}

/// Largest distance from dense area-weighted samples of `a` to `b` (a lower bound of the
/// one-sided Hausdorff distance).
pub fn dense_max(a: &TriMesh, b: &TriMesh, n: usize, seed: u64) -> f64 {
    let s = occupancy::sample::SurfaceSampler::from_mesh(a).unwrap().sample(n, seed);
    let oracle = occupancy::MeshOracle::from_mesh(b, &occupancy::Config::default()).unwrap();
    let c = oracle.closest_points(&s.points).unwrap();
    c.iter().map(|c| c.squared_distance.sqrt()).fold(0.0, f64::max)
}

pub fn bunny() -> TriMesh {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/bunny.obj");
    mesh_io::read_mesh(&root).unwrap()
}
