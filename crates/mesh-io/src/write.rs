//! Writing meshes: GLB, glTF + .bin, OBJ and binary PLY, always atomically.

use std::borrow::Cow;
use std::collections::BTreeMap;

use std::path::Path;

use gltf_json as json;
use json::validation::Checked::Valid;
use json::validation::USize64;

use crate::atomic::{atomic_write, prepare};
use crate::error::MeshError;
use crate::output::OutputFormat;
use crate::TriMesh;

/// One mesh of a glTF scene: becomes one node with one triangle primitive.
#[derive(Clone, Copy, Debug)]
pub struct SceneMesh<'a> {
    /// Node and mesh name.
    pub name: &'a str,
    /// The triangles.
    pub mesh: &'a TriMesh,
    /// Optional per-vertex colours: #V×3 f32 linear RGB in [0, 1] (clamped on write).
    pub colors: Option<&'a [[f32; 3]]>,
    /// The normals written with it ([`Normals`]).
    pub normals: Normals,
}

/// The vertex normals a glTF file carries, which is how viewers shade it.
///
/// Measured on crusts (`benches/render.py --smooth`, docs/viewer.md): with one
/// area-weighted normal per vertex, every sharp edge of a CAD part shades as a ragged,
/// blotchy band, because a crust vertex on an edge averages faces of both sides and the
/// crust's small faces at odd angles there; a vertex can hold only one normal, so no choice
/// of it fixes that while the vertex is shared.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Normals {
    /// No NORMAL attribute: glTF viewers must then shade each triangle flat (the glTF 2.0
    /// specification, *Meshes*). Every vertex stays shared, so the file is as watertight for
    /// readers that do not weld (trimesh, libigl) as the mesh. The default: what you see is
    /// the polyhedron, as with OBJ and PLY, which carry no normals either.
    #[default]
    Flat,
    /// One area-weighted normal per vertex, vertices shared: smooth shading, good on smooth
    /// shapes, blotchy along sharp edges.
    Smooth,
    /// Normals smoothed only between faces less than this many degrees apart (in (0, 180)):
    /// each face corner takes the area-weighted normal of the faces at its vertex within the
    /// angle of that face, and the corners of a vertex with the same normal share one copy
    /// of it (`crease_split`). Smooth shapes shade smooth and sharp edges stay sharp, but a
    /// vertex on a crease is written once per side: readers that weld by position (voronoi-fit, Blender) see the same closed
    /// surface, readers that do not (trimesh without `merge_vertices(merge_norm=True)`) see
    /// seams.
    Crease(f64),
}

impl Normals {
    /// Parses `flat`, `smooth`, `crease` (40°) or `crease:DEG`.
    ///
    /// # Errors
    /// A message naming the accepted forms.
    pub fn parse(s: &str) -> Result<Normals, String> {
        let bad = || format!("normals {s:?}: expected flat, smooth, crease or crease:DEGREES with 0 < DEGREES < 180");
        match s.trim() {
            "flat" => Ok(Normals::Flat),
            "smooth" => Ok(Normals::Smooth),
            "crease" => Ok(Normals::Crease(DEFAULT_CREASE_DEGREES)),
            t => {
                let d: f64 = t.strip_prefix("crease:").ok_or_else(bad)?.trim().parse().map_err(|_| bad())?;
                if d > 0.0 && d < 180.0 {
                    Ok(Normals::Crease(d))
                } else {
                    Err(bad())
                }
            }
        }
    }
}

impl std::fmt::Display for Normals {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Normals::Flat => write!(f, "flat"),
            Normals::Smooth => write!(f, "smooth"),
            Normals::Crease(d) => write!(f, "crease:{d}"),
        }
    }
}

/// The crease angle of plain `crease`: above the ~27° at which a crust's faces between
/// neighbouring pairs lean on smooth shapes (docs/main-job.md, *Polish*), so those shade
/// smooth, and well below the 90° of a CAD part's edges.
pub const DEFAULT_CREASE_DEGREES: f64 = 40.0;

/// The on-disk layout of a glTF scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GltfLayout {
    /// One `.glb` file.
    Binary,
    /// A `.gltf` JSON file and a `.bin` beside it with the same stem.
    Separate,
}

/// Write `mesh` to `path` in the format its extension names: `.glb`, `.gltf`, `.obj` or
/// `.ply` (binary little-endian).
///
/// # Errors
/// [`crate::ErrorKind::UnknownFormat`] for another extension ([`OutputFormat::from_path`]);
/// [`crate::ErrorKind::Write`] when the file cannot be written (nothing is left behind).
pub fn write_mesh(path: &Path, mesh: &TriMesh) -> Result<(), MeshError> {
    write_mesh_with(path, mesh, Normals::default())
}

/// [`write_mesh`] with the normals a glTF file carries (OBJ and PLY are written without
/// normals whatever `normals` says).
///
/// # Errors
/// As [`write_mesh`].
pub fn write_mesh_with(path: &Path, mesh: &TriMesh, normals: Normals) -> Result<(), MeshError> {
    let scene = || [SceneMesh { name: "mesh", mesh, colors: None, normals }];
    match OutputFormat::from_path(path)? {
        OutputFormat::Glb => write_gltf(path, &scene(), GltfLayout::Binary),
        OutputFormat::Gltf => write_gltf(path, &scene(), GltfLayout::Separate),
        OutputFormat::Obj => write_obj(path, mesh),
        OutputFormat::Ply => write_ply(path, mesh),
    }
}

/// Area-weighted vertex normals, unit length in f32. A vertex without a face of non-zero
/// area gets +Z, so that every normal is a valid unit vector as glTF requires.
pub fn vertex_normals(mesh: &TriMesh) -> Vec<[f32; 3]> {
    let mut acc = vec![[0.0f64; 3]; mesh.positions.len()];
    for &t in &mesh.triangles {
        let n = face_normal(mesh, t);
        for &i in &t {
            for k in 0..3 {
                acc[i as usize][k] += n[k];
            }
        }
    }
    acc.into_iter().map(unit_f32).collect()
}

/// A mesh as glTF stores it: vertices split where [`Normals::Crease`] asks (`source[i]` is
/// the mesh vertex that vertex `i` copies), with its normals (`None` for flat).
struct Shaded {
    source: Vec<u32>,
    normals: Option<Vec<[f32; 3]>>,
    triangles: Vec<[u32; 3]>,
}

fn unit_f32(n: [f64; 3]) -> [f32; 3] {
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if len > 0.0 && len.is_finite() {
        [(n[0] / len) as f32, (n[1] / len) as f32, (n[2] / len) as f32]
    } else {
        [0.0, 0.0, 1.0]
    }
}

fn face_normal(mesh: &TriMesh, t: [u32; 3]) -> [f64; 3] {
    let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
    let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
}

fn shade(mesh: &TriMesh, normals: Normals) -> Shaded {
    let identity = || (0..mesh.positions.len() as u32).collect();
    match normals {
        Normals::Flat => Shaded { source: identity(), normals: None, triangles: mesh.triangles.clone() },
        Normals::Smooth => {
            Shaded { source: identity(), normals: Some(vertex_normals(mesh)), triangles: mesh.triangles.clone() }
        }
        Normals::Crease(degrees) => crease_split(mesh, degrees),
    }
}

/// [`Normals::Crease`]: each corner of a face takes the area-weighted normal of the faces
/// at its vertex within `degrees` of that face (a face of zero area counts as within any
/// angle), and corners of a vertex with the same normal share one copy of it. The rule is
/// per face, not grouped across edges: a crust meets a CAD edge in a staircase of small
/// faces at in-between angles, and grouping faces joined by gentle bends chains across
/// the edge and smooths it (tried: rendered, the edges and the letters of a 20 mm test cube
/// came out blotchy). Written here: a few lines over the mesh's own adjacency; no mesh
/// crate in the tree does it for an indexed mesh.
fn crease_split(mesh: &TriMesh, degrees: f64) -> Shaded {
    let nv = mesh.positions.len();
    let cos = degrees.to_radians().cos();
    let fnormal: Vec<[f64; 3]> = mesh.triangles.iter().map(|&t| face_normal(mesh, t)).collect();
    let unit: Vec<Option<[f64; 3]>> = fnormal
        .iter()
        .map(|n| {
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            (len > 0.0 && len.is_finite()).then(|| n.map(|x| x / len))
        })
        .collect();
    // Faces around each vertex (CSR, in face order, so that a vertex whose faces are all
    // within the angle gets exactly `vertex_normals`' sum).
    let mut start = vec![0usize; nv + 1];
    for t in &mesh.triangles {
        for &v in t {
            start[v as usize + 1] += 1;
        }
    }
    for i in 0..nv {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut around = vec![0u32; start[nv]];
    for (f, t) in mesh.triangles.iter().enumerate() {
        for &v in t {
            around[fill[v as usize]] = f as u32;
            fill[v as usize] += 1;
        }
    }
    let mut source = Vec::with_capacity(nv);
    let mut out_normals: Vec<[f32; 3]> = Vec::with_capacity(nv);
    let mut corner = vec![[0u32; 3]; mesh.triangles.len()];
    let mut copies: Vec<([f32; 3], u32)> = Vec::new();
    for v in 0..nv {
        let fs = &around[start[v]..start[v + 1]];
        copies.clear();
        for &f in fs {
            let n = fs
                .iter()
                .filter(|&&g| match (unit[f as usize], unit[g as usize]) {
                    (Some(a), Some(b)) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2] >= cos,
                    _ => true,
                })
                .fold([0.0; 3], |s, &g| {
                    let n = fnormal[g as usize];
                    [s[0] + n[0], s[1] + n[1], s[2] + n[2]]
                });
            let n = unit_f32(n);
            let index = match copies.iter().find(|c| c.0 == n) {
                Some(c) => c.1,
                None => {
                    let i = source.len() as u32;
                    source.push(v as u32);
                    out_normals.push(n);
                    copies.push((n, i));
                    i
                }
            };
            let t = mesh.triangles[f as usize];
            for k in 0..3 {
                if t[k] as usize == v {
                    corner[f as usize][k] = index;
                }
            }
        }
        if fs.is_empty() {
            // An unreferenced vertex keeps a place (the mesh had it; glTF allows it).
            source.push(v as u32);
            out_normals.push([0.0, 0.0, 1.0]);
        }
    }
    Shaded { source, normals: Some(out_normals), triangles: corner }
}

fn push_bytes(bin: &mut Vec<u8>, data: impl Iterator<Item = [u8; 4]>) -> (usize, usize) {
    let start = bin.len();
    for b in data {
        bin.extend_from_slice(&b);
    }
    (start, bin.len() - start)
}

fn view(
    root: &mut json::Root,
    buffer: json::Index<json::Buffer>,
    span: (usize, usize),
    target: json::buffer::Target,
) -> json::Index<json::buffer::View> {
    root.push(json::buffer::View {
        buffer,
        byte_length: USize64::from(span.1),
        byte_offset: Some(USize64::from(span.0)),
        byte_stride: None,
        extensions: Default::default(),
        extras: Default::default(),
        name: None,
        target: Some(Valid(target)),
    })
}

fn accessor(
    root: &mut json::Root,
    view: json::Index<json::buffer::View>,
    count: usize,
    component: json::accessor::ComponentType,
    ty: json::accessor::Type,
    bounds: Option<([f32; 3], [f32; 3])>,
) -> json::Index<json::Accessor> {
    root.push(json::Accessor {
        buffer_view: Some(view),
        byte_offset: None,
        count: USize64::from(count),
        component_type: Valid(json::accessor::GenericComponentType(component)),
        extensions: Default::default(),
        extras: Default::default(),
        type_: Valid(ty),
        min: bounds.map(|b| json::Value::from(b.0.to_vec())),
        max: bounds.map(|b| json::Value::from(b.1.to_vec())),
        name: None,
        normalized: false,
        sparse: None,
    })
}

/// Build the glTF document and its binary buffer for a scene.
fn build_scene(meshes: &[SceneMesh], bin_uri: Option<String>) -> (json::Root, Vec<u8>) {
    use json::accessor::{ComponentType as C, Type as T};
    use json::buffer::Target;
    let mut root = json::Root {
        asset: json::Asset {
            generator: Some(format!("voronoi-fit {}", env!("CARGO_PKG_VERSION"))),
            ..Default::default()
        },
        ..Default::default()
    };
    let mut bin = Vec::new();
    let total: usize = meshes.iter().filter(|m| !m.mesh.triangles.is_empty()).map(|m| m.mesh.positions.len()).sum();
    // The buffer entry is created only if some mesh has data: glTF forbids empty buffers.
    let buffer = (total > 0).then(|| {
        root.push(json::Buffer {
            byte_length: USize64(0),
            extensions: None,
            extras: Default::default(),
            name: None,
            uri: bin_uri,
        })
    });
    let mut nodes = Vec::new();
    for m in meshes {
        let mut node = json::Node { name: Some(m.name.to_string()), ..Default::default() };
        if let (Some(buffer), false) = (buffer, m.mesh.triangles.is_empty()) {
            let shaded = shade(m.mesh, m.normals);
            let pos: Vec<[f32; 3]> =
                shaded.source.iter().map(|&i| m.mesh.positions[i as usize].map(|c| c as f32)).collect();
            let mut lo = [f32::INFINITY; 3];
            let mut hi = [f32::NEG_INFINITY; 3];
            for p in &pos {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
            let span = push_bytes(&mut bin, pos.iter().flat_map(|p| p.map(f32::to_le_bytes)));
            let v = view(&mut root, buffer, span, Target::ArrayBuffer);
            let positions = accessor(&mut root, v, pos.len(), C::F32, T::Vec3, Some((lo, hi)));
            let mut attributes = BTreeMap::new();
            attributes.insert(Valid(json::mesh::Semantic::Positions), positions);
            if let Some(normals) = &shaded.normals {
                let span = push_bytes(&mut bin, normals.iter().flat_map(|p| p.map(f32::to_le_bytes)));
                let v = view(&mut root, buffer, span, Target::ArrayBuffer);
                let normals = accessor(&mut root, v, pos.len(), C::F32, T::Vec3, None);
                attributes.insert(Valid(json::mesh::Semantic::Normals), normals);
            }
            if let Some(colors) = m.colors {
                let colors: Vec<[f32; 3]> =
                    shaded.source.iter().map(|&i| colors.get(i as usize).copied().unwrap_or([1.0; 3])).collect();
                let span = push_bytes(&mut bin, colors.iter().flat_map(|c| c.map(|x| x.clamp(0.0, 1.0).to_le_bytes())));
                let v = view(&mut root, buffer, span, Target::ArrayBuffer);
                let colors = accessor(&mut root, v, colors.len(), C::F32, T::Vec3, None);
                attributes.insert(Valid(json::mesh::Semantic::Colors(0)), colors);
            }
            let span = push_bytes(&mut bin, shaded.triangles.iter().flatten().map(|i| i.to_le_bytes()));
            let v = view(&mut root, buffer, span, Target::ElementArrayBuffer);
            let indices = accessor(&mut root, v, 3 * shaded.triangles.len(), C::U32, T::Scalar, None);
            let mesh = root.push(json::Mesh {
                extensions: Default::default(),
                extras: Default::default(),
                name: Some(m.name.to_string()),
                primitives: vec![json::mesh::Primitive {
                    attributes,
                    extensions: Default::default(),
                    extras: Default::default(),
                    indices: Some(indices),
                    material: None,
                    mode: Valid(json::mesh::Mode::Triangles),
                    targets: None,
                }],
                weights: None,
            });
            node.mesh = Some(mesh);
        }
        nodes.push(root.push(node));
    }
    if let Some(b) = buffer {
        root.buffers[b.value()].byte_length = USize64::from(bin.len());
    }
    let scene =
        root.push(json::Scene { extensions: Default::default(), extras: Default::default(), name: None, nodes });
    root.scene = Some(scene);
    (root, bin)
}

/// Write a scene of meshes as glTF 2.0, one node per mesh, positions as f32 with exact
/// min/max, the normals each mesh asks for ([`Normals`]), optional vertex colours and u32
/// indices. Meshes with no triangle become empty nodes (an empty crust is a valid result,
/// not an error).
///
/// # Errors
/// [`crate::ErrorKind::Write`] when a file cannot be written; nothing partial is left.
pub fn write_gltf(path: &Path, meshes: &[SceneMesh], layout: GltfLayout) -> Result<(), MeshError> {
    let ser_err = |e: json::Error| MeshError::write(path, std::io::Error::other(e));
    match layout {
        GltfLayout::Binary => {
            let (root, bin) = build_scene(meshes, None);
            let json_bytes = json::serialize::to_vec(&root).map_err(ser_err)?;
            let glb = gltf::binary::Glb {
                header: gltf::binary::Header { magic: *b"glTF", version: 2, length: 0 },
                json: Cow::Owned(json_bytes),
                bin: (!bin.is_empty()).then_some(Cow::Owned(bin)),
            };
            atomic_write(path, |w| glb.to_writer(w).map_err(std::io::Error::other))
        }
        GltfLayout::Separate => {
            let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "mesh".into());
            let bin_name = format!("{stem}.bin");
            let bin_path = path.with_file_name(&bin_name);
            let (root, bin) = build_scene(meshes, Some(bin_name));
            let json_bytes = json::serialize::to_vec_pretty(&root).map_err(ser_err)?;
            // Both files are written to temporaries first; the .bin is renamed into place
            // only once the .gltf is ready too, and removed again if the .gltf rename fails.
            let bin_tmp = (!bin.is_empty()).then(|| prepare(&bin_path, |w| w.write_all(&bin))).transpose()?;
            let gltf_tmp = prepare(path, |w| w.write_all(&json_bytes))?;
            if let Some(t) = bin_tmp {
                t.persist(&bin_path).map_err(|e| MeshError::write(&bin_path, e.error))?;
            }
            if let Err(e) = gltf_tmp.persist(path) {
                let _ = std::fs::remove_file(&bin_path);
                return Err(MeshError::write(path, e.error));
            }
            Ok(())
        }
    }
}

/// Write Wavefront OBJ: `v` lines with shortest round-trip decimal f64 (lossless), 1-based
/// `f` lines.
pub fn write_obj(path: &Path, mesh: &TriMesh) -> Result<(), MeshError> {
    atomic_write(path, |w| {
        writeln!(
            w,
            "# voronoi-fit {}: {} vertices, {} triangles",
            env!("CARGO_PKG_VERSION"),
            mesh.positions.len(),
            mesh.triangles.len()
        )?;
        for p in &mesh.positions {
            writeln!(w, "v {:?} {:?} {:?}", p[0], p[1], p[2])?;
        }
        for t in &mesh.triangles {
            writeln!(w, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
        }
        Ok(())
    })
}

/// Write binary little-endian PLY with double coordinates (lossless) and u32 indices.
pub fn write_ply(path: &Path, mesh: &TriMesh) -> Result<(), MeshError> {
    atomic_write(path, |w| {
        write!(
            w,
            "ply\nformat binary_little_endian 1.0\ncomment voronoi-fit {}\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\nelement face {}\nproperty list uchar uint vertex_indices\nend_header\n",
            env!("CARGO_PKG_VERSION"),
            mesh.positions.len(),
            mesh.triangles.len()
        )?;
        for p in &mesh.positions {
            for c in p {
                w.write_all(&c.to_le_bytes())?;
            }
        }
        for t in &mesh.triangles {
            w.write_all(&[3u8])?;
            for i in t {
                w.write_all(&i.to_le_bytes())?;
            }
        }
        Ok(())
    })
}
