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
    pub mesh: &'a TriMesh,
    /// Optional per-vertex colours: #V×3 f32 linear RGB in [0, 1] (clamped on write).
    pub colors: Option<&'a [[f32; 3]]>,
}

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
    let scene = || [SceneMesh { name: "mesh", mesh, colors: None }];
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
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
        let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
        for &i in t {
            for k in 0..3 {
                acc[i as usize][k] += n[k];
            }
        }
    }
    acc.iter()
        .map(|n| {
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if len > 0.0 && len.is_finite() {
                [(n[0] / len) as f32, (n[1] / len) as f32, (n[2] / len) as f32]
            } else {
                [0.0, 0.0, 1.0]
            }
        })
        .collect()
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
            let pos: Vec<[f32; 3]> = m.mesh.positions.iter().map(|p| p.map(|c| c as f32)).collect();
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
            let normals = vertex_normals(m.mesh);
            let span = push_bytes(&mut bin, normals.iter().flat_map(|p| p.map(f32::to_le_bytes)));
            let v = view(&mut root, buffer, span, Target::ArrayBuffer);
            let normals = accessor(&mut root, v, pos.len(), C::F32, T::Vec3, None);
            let mut attributes = BTreeMap::new();
            attributes.insert(Valid(json::mesh::Semantic::Positions), positions);
            attributes.insert(Valid(json::mesh::Semantic::Normals), normals);
            if let Some(colors) = m.colors {
                let span = push_bytes(&mut bin, colors.iter().flat_map(|c| c.map(|x| x.clamp(0.0, 1.0).to_le_bytes())));
                let v = view(&mut root, buffer, span, Target::ArrayBuffer);
                let colors = accessor(&mut root, v, colors.len(), C::F32, T::Vec3, None);
                attributes.insert(Valid(json::mesh::Semantic::Colors(0)), colors);
            }
            let span = push_bytes(&mut bin, m.mesh.triangles.iter().flatten().map(|i| i.to_le_bytes()));
            let v = view(&mut root, buffer, span, Target::ElementArrayBuffer);
            let indices = accessor(&mut root, v, 3 * m.mesh.triangles.len(), C::U32, T::Scalar, None);
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
/// min/max, area-weighted normals, optional vertex colours and u32 indices. Meshes with no
/// triangle become empty nodes (an empty crust is a valid result, not an error).
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
