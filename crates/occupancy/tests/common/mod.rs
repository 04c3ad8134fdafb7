//! Test meshes grouped by class (closed genus 0, open, soup, ...), so every algorithm is
//! tried on every class. Shared by the integration tests and the benches.
//!
//! Readers here are deliberately tiny (binary STL, ASCII PLY) and only serve the shared
//! test meshes; the product reads meshes through `mesh-io`.

#![allow(dead_code)]

use std::collections::HashMap;
use std::path::PathBuf;

pub type Mesh = (Vec<[f64; 3]>, Vec<[u32; 3]>);

/// Directory of the shared meshes: `$VF_SHARED_MESHES` (the name the rest of the test
/// suite reads; `$VF_MESHES` is still accepted), else `../shared/meshes` beside the repo.
pub fn shared_meshes_dir() -> PathBuf {
    if let Some(d) = std::env::var_os("VF_SHARED_MESHES").or_else(|| std::env::var_os("VF_MESHES")) {
        return PathBuf::from(d);
    }
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/meshes")
}

/// Loads a shared mesh by file name, or `None` when the shared folder is absent.
pub fn shared_mesh(name: &str) -> Option<Mesh> {
    let path = shared_meshes_dir().join(name);
    let bytes = std::fs::read(&path).ok()?;
    let lower = name.to_ascii_lowercase();
    if lower.ends_with(".stl") {
        Some(read_binary_stl(&bytes))
    } else if lower.ends_with(".ply") {
        Some(read_ascii_ply(&bytes))
    } else {
        let m = mesh_io::read_mesh(&path).unwrap_or_else(|e| panic!("test helper cannot read {name}: {e}"));
        Some((m.positions, m.triangles))
    }
}

/// The examples' command line `N MESH...`: N and each mesh file (read with mesh-io) with
/// its file stem.
#[allow(dead_code)]
pub fn count_and_meshes_from_args() -> (usize, Vec<(String, Mesh)>) {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|a| a.parse().ok()).expect("usage: N MESH...");
    let meshes = args[2..]
        .iter()
        .map(|path| {
            let p = std::path::Path::new(path);
            let m = mesh_io::read_mesh(p).unwrap_or_else(|e| panic!("{path}: {e}"));
            (p.file_stem().unwrap_or_default().to_string_lossy().to_string(), (m.positions, m.triangles))
        })
        .collect();
    (n, meshes)
}

/// Binary or ASCII STL, vertices welded by exact position (as mesh readers usually do).
pub fn read_binary_stl(bytes: &[u8]) -> Mesh {
    if bytes.starts_with(b"solid") && bytes.len() >= 84 {
        let n = u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as usize;
        if bytes.len() != 84 + 50 * n {
            return read_ascii_stl(std::str::from_utf8(bytes).unwrap());
        }
    }
    let n = u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as usize;
    assert_eq!(bytes.len(), 84 + 50 * n, "not a binary STL");
    let mut map: HashMap<[u32; 3], u32> = HashMap::new();
    let mut positions = Vec::new();
    let mut triangles = Vec::with_capacity(n);
    for f in 0..n {
        let base = 84 + 50 * f + 12;
        let mut tri = [0u32; 3];
        for (c, t) in tri.iter_mut().enumerate() {
            let mut key = [0u32; 3];
            let mut p = [0f64; 3];
            for k in 0..3 {
                let o = base + 12 * c + 4 * k;
                let v = f32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
                key[k] = v.to_bits();
                p[k] = v as f64;
            }
            *t = *map.entry(key).or_insert_with(|| {
                positions.push(p);
                (positions.len() - 1) as u32
            });
        }
        triangles.push(tri);
    }
    (positions, triangles)
}

fn read_ascii_stl(text: &str) -> Mesh {
    let mut map: HashMap<[u64; 3], u32> = HashMap::new();
    let mut positions = Vec::new();
    let mut ids = Vec::new();
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        if w.len() == 4 && w[0] == "vertex" {
            let p = [w[1], w[2], w[3]].map(|x| x.parse::<f64>().unwrap());
            let key = p.map(|x| (x as f32).to_bits() as u64);
            ids.push(*map.entry(key).or_insert_with(|| {
                positions.push(p.map(|x| x as f32 as f64));
                (positions.len() - 1) as u32
            }));
        }
    }
    let triangles = ids.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
    (positions, triangles)
}

/// ASCII PLY with `x y z` first among the vertex properties and triangle faces.
pub fn read_ascii_ply(bytes: &[u8]) -> Mesh {
    let text = std::str::from_utf8(bytes).unwrap();
    let mut lines = text.lines();
    let (mut nv, mut nf) = (0usize, 0usize);
    for line in lines.by_ref() {
        let w: Vec<&str> = line.split_whitespace().collect();
        if w.len() == 3 && w[0] == "element" && w[1] == "vertex" {
            nv = w[2].parse().unwrap();
        }
        if w.len() == 3 && w[0] == "element" && w[1] == "face" {
            nf = w[2].parse().unwrap();
        }
        if line.trim() == "end_header" {
            break;
        }
    }
    let mut positions = Vec::with_capacity(nv);
    for _ in 0..nv {
        let w: Vec<f64> = lines.next().unwrap().split_whitespace().map(|x| x.parse().unwrap()).collect();
        positions.push([w[0], w[1], w[2]]);
    }
    let mut triangles = Vec::with_capacity(nf);
    for _ in 0..nf {
        let w: Vec<u32> = lines.next().unwrap().split_whitespace().map(|x| x.parse().unwrap()).collect();
        assert_eq!(w[0], 3, "only triangles");
        triangles.push([w[1], w[2], w[3]]);
    }
    (positions, triangles)
}

/// Unit icosphere with `20·4^subdivisions` faces, counter-clockwise seen from outside
/// (`mesh_io::shapes::icosphere`).
pub fn icosphere(subdivisions: u32) -> Mesh {
    let m = mesh_io::shapes::icosphere(subdivisions);
    (m.positions, m.triangles)
}

/// Welded two-torus-like genus-1 mesh: a torus with radii (1, 0.35), `nu`×`nv` quads.
pub fn torus(nu: u32, nv: u32) -> Mesh {
    let mut positions = Vec::new();
    for i in 0..nu {
        for j in 0..nv {
            let u = 2.0 * std::f64::consts::PI * i as f64 / nu as f64;
            let v = 2.0 * std::f64::consts::PI * j as f64 / nv as f64;
            let r = 1.0 + 0.35 * v.cos();
            positions.push([r * u.cos(), r * u.sin(), 0.35 * v.sin()]);
        }
    }
    let id = |i: u32, j: u32| (i % nu) * nv + (j % nv);
    let mut triangles = Vec::new();
    for i in 0..nu {
        for j in 0..nv {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    (positions, triangles)
}

/// Every triangle with its own three vertices (an unwelded soup of the same surface).
pub fn unweld((p, t): &Mesh) -> Mesh {
    let mut positions = Vec::with_capacity(3 * t.len());
    let mut triangles = Vec::with_capacity(t.len());
    for tri in t {
        let base = positions.len() as u32;
        for &v in tri {
            positions.push(p[v as usize]);
        }
        triangles.push([base, base + 1, base + 2]);
    }
    (positions, triangles)
}

/// Test meshes by class: (class/name, mesh). Shared meshes are skipped when absent.
pub fn meshes_by_class() -> Vec<(String, Mesh)> {
    let mut out = vec![
        ("closed-genus0/icosphere3".to_string(), icosphere(3)),
        ("closed-genus1/torus".to_string(), torus(48, 24)),
        ("soup/icosphere2-unwelded".to_string(), unweld(&icosphere(2))),
    ];
    // Open: an icosphere with a cap of faces removed.
    let (p, t) = icosphere(3);
    let open: Vec<[u32; 3]> =
        t.iter().copied().filter(|tri| tri.iter().map(|&v| p[v as usize][2]).sum::<f64>() / 3.0 < 0.7).collect();
    out.push(("open/icosphere3-holed".to_string(), (p, open)));
    // Multi-body: two overlapping spheres (non-manifold union of two closed surfaces).
    let (mut p2, mut t2) = icosphere(2);
    let (q, s) = icosphere(2);
    let base = p2.len() as u32;
    p2.extend(q.iter().map(|v| [v[0] + 0.8, v[1], v[2]]));
    t2.extend(s.iter().map(|tri| [tri[0] + base, tri[1] + base, tri[2] + base]));
    out.push(("multibody/two-spheres".to_string(), (p2, t2)));
    for (class, name) in [
        ("open", "mikedh__bunny.ply"),
        ("open", "mikedh__teapot.stl"),
        ("soup", "mikedh__soup.stl"),
        ("multibody", "mikedh__multibody.stl"),
    ] {
        if let Some(m) = shared_mesh(name) {
            out.push((format!("{class}/{name}"), m));
        }
    }
    out
}

/// The query set of the issue: half uniform in the bounding box grown by 10%, half area-
/// weighted surface samples plus Gaussian noise with σ = 1% of the box diagonal.
pub fn issue_queries(mesh: &Mesh, n: usize, seed: u64) -> Vec<[f64; 3]> {
    let (p, t) = mesh;
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for v in p {
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    let diag = ((0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>()).sqrt();
    let mut glo = lo;
    let mut ghi = hi;
    for k in 0..3 {
        let pad = 0.05 * (hi[k] - lo[k]);
        glo[k] -= pad;
        ghi[k] += pad;
    }
    let mut q = occupancy::sample::uniform_in_box(glo, ghi, n / 2, seed).unwrap();
    let sampler = occupancy::sample::SurfaceSampler::new(p, t).unwrap();
    q.extend(occupancy::sample::near_surface(&sampler, n - n / 2, &[0.01 * diag], seed).unwrap());
    q
}

/// Mean work of one fast winding query over `queries` (`[nodes visited, expansions,
/// triangles summed exactly]`, from [`occupancy::MeshOracle::winding_work`]).
pub fn fast_work_per_query(oracle: &occupancy::MeshOracle, queries: &[[f64; 3]]) -> [f64; 3] {
    let mut ws = occupancy::Workspace::new();
    let mut total = [0u64; 3];
    for q in queries {
        let c = oracle.winding_work(*q, occupancy::WindingMode::Fast, &mut ws);
        for k in 0..3 {
            total[k] += c[k];
        }
    }
    total.map(|t| t as f64 / queries.len().max(1) as f64)
}
