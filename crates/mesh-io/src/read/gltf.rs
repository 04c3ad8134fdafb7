//! glTF 2.0 (`.gltf` with external or data-URI buffers, and `.glb`) through the `gltf` crate.
//!
//! The `gltf` crate parses and validates the JSON; accessor data is read here with every
//! offset checked against the buffer, because the crate's own readers assume the buffers
//! match the JSON and can panic on a file that lies about lengths. Every triangle
//! primitive (triangles, strips, fans) of every node of the default scene is read, with
//! the node's world transform applied in f64; a transform with a negative determinant
//! flips the winding so triangles stay counter-clockwise seen from outside.

use std::path::Path;

use base64::Engine as _;
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;

use crate::error::{ErrorKind, Location, MeshError, Result};
use crate::TriMesh;

type Mat4 = [[f64; 4]; 4]; // column-major, as glTF stores it

pub(crate) fn read(bytes: &[u8], path: &Path) -> Result<TriMesh> {
    // gltf 1.4 subtracts the header size from the declared length without checking it
    // (an overflow panic on a GLB declaring fewer than 12 bytes): check it here first.
    // Regression: found by tests/no_panic.rs.
    if bytes.starts_with(b"glTF") && bytes.len() >= 12 {
        let declared = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]);
        if declared < 12 {
            return Err(MeshError::new(
                ErrorKind::Syntax,
                path,
                Location::Byte(8),
                format!("not a valid glTF 2.0 file: the GLB header declares a total length of {declared} bytes, less than the header itself"),
            ));
        }
    }
    check_attribute_indices(bytes, path)?;
    let gltf = gltf::Gltf::from_slice(bytes).map_err(|e| {
        let kind = match e {
            gltf::Error::Binary(_) if bytes.starts_with(b"glTF") => ErrorKind::Truncated,
            _ => ErrorKind::Syntax,
        };
        MeshError::new(kind, path, Location::File, format!("not a valid glTF 2.0 file: {e}"))
    })?;
    let buffers = load_buffers(&gltf, path)?;
    let doc = &gltf.document;
    let scene = doc.default_scene().or_else(|| doc.scenes().next()).ok_or_else(|| {
        MeshError::new(ErrorKind::Empty, path, Location::File, "the file defines no scene")
            .hint("Export the glTF with a scene that contains the mesh nodes.")
    })?;

    let mut mesh = TriMesh::default();
    let mut skipped_modes: Vec<String> = Vec::new();
    // Iterative traversal with a depth limit: a malicious file with a cyclic node graph must
    // not overflow the stack.
    let mut stack: Vec<(gltf::Node, Mat4, usize)> = scene.nodes().map(|n| (n, IDENTITY, 0)).collect();
    while let Some((node, parent, depth)) = stack.pop() {
        if depth > 256 {
            return Err(MeshError::new(
                ErrorKind::Syntax,
                path,
                Location::Element { kind: "node", index: node.index() },
                "the node hierarchy is deeper than 256 levels (a cycle?)",
            ));
        }
        let local = node.transform().matrix().map(|c| c.map(f64::from));
        let world = mul(&parent, &local);
        if let Some(m) = node.mesh() {
            for prim in m.primitives() {
                read_primitive(&prim, &world, &buffers, path, &mut mesh, &mut skipped_modes, m.index())?;
            }
        }
        for child in node.children() {
            stack.push((child, world, depth + 1));
        }
    }
    if mesh.triangles.is_empty() {
        let msg = if skipped_modes.is_empty() {
            "the default scene has no mesh with triangles".to_string()
        } else {
            format!("the default scene has only non-triangle primitives ({})", skipped_modes.join(", "))
        };
        return Err(MeshError::new(ErrorKind::Unsupported, path, Location::File, msg)
            .hint("Only triangle primitives (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN) describe a surface."));
    }
    Ok(mesh)
}

/// gltf-json 1.4's primitive validation indexes `accessors` with the POSITION attribute's
/// index before checking its range (a panic on a file with a dangling index). Deserialise
/// the JSON once without validation and check every attribute index first.
/// Regression: found by tests/no_panic.rs.
fn check_attribute_indices(bytes: &[u8], path: &Path) -> Result<()> {
    let json: &[u8] = if bytes.starts_with(b"glTF") {
        match gltf::binary::Glb::from_slice(bytes) {
            Ok(glb) => return check_json(&glb.json, path),
            Err(_) => return Ok(()), // Gltf::from_slice reports it properly
        }
    } else {
        bytes
    };
    check_json(json, path)
}

fn check_json(json: &[u8], path: &Path) -> Result<()> {
    let Ok(root) = serde_json::from_slice::<gltf_json::Root>(json) else {
        return Ok(()); // Gltf::from_slice reports the syntax error
    };
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (k, prim) in mesh.primitives.iter().enumerate() {
            for (semantic, index) in &prim.attributes {
                if index.value() >= root.accessors.len() {
                    return Err(MeshError::new(
                        ErrorKind::Syntax,
                        path,
                        Location::Element { kind: "mesh", index: m },
                        format!(
                            "not a valid glTF 2.0 file: primitive {k} of mesh {m} uses accessor {} for {semantic:?}, but the file has {} accessors",
                            index.value(),
                            root.accessors.len()
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

const IDENTITY: Mat4 = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]];

fn mul(a: &Mat4, b: &Mat4) -> Mat4 {
    let mut c = [[0.0; 4]; 4];
    for (col, bc) in b.iter().enumerate() {
        for row in 0..4 {
            c[col][row] = (0..4).map(|k| a[k][row] * bc[k]).sum();
        }
    }
    c
}

fn det3(m: &Mat4) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[2][1] * m[1][2]) - m[1][0] * (m[0][1] * m[2][2] - m[2][1] * m[0][2])
        + m[2][0] * (m[0][1] * m[1][2] - m[1][1] * m[0][2])
}

fn load_buffers(gltf: &gltf::Gltf, path: &Path) -> Result<Vec<Vec<u8>>> {
    let mut out = Vec::new();
    for buf in gltf.document.buffers() {
        let loc = Location::Element { kind: "buffer", index: buf.index() };
        let data = match buf.source() {
            gltf::buffer::Source::Bin => gltf.blob.clone().ok_or_else(|| {
                MeshError::new(ErrorKind::Truncated, path, loc.clone(), "the GLB has no binary chunk for its buffer")
            })?,
            gltf::buffer::Source::Uri(uri) => {
                if let Some(rest) = uri.strip_prefix("data:") {
                    let b64 = rest.split_once(";base64,").map(|(_, d)| d).ok_or_else(|| {
                        MeshError::new(ErrorKind::Unsupported, path, loc.clone(), "a data URI that is not base64")
                    })?;
                    base64::engine::general_purpose::STANDARD.decode(b64).map_err(|e| {
                        MeshError::new(
                            ErrorKind::Syntax,
                            path,
                            loc.clone(),
                            format!("the base64 data URI is corrupt ({e})"),
                        )
                    })?
                } else {
                    let file = path.parent().unwrap_or(Path::new(".")).join(percent_decode(uri));
                    std::fs::read(&file).map_err(|e| {
                        MeshError::new(
                            ErrorKind::Io,
                            path,
                            loc.clone(),
                            format!("cannot read the buffer file {} ({e})", file.display()),
                        )
                        .hint("Keep the .bin file next to the .gltf, or export a single .glb.")
                    })?
                }
            }
        };
        if data.len() < buf.length() {
            return Err(MeshError::new(
                ErrorKind::Truncated,
                path,
                loc,
                format!("the buffer declares {} bytes but holds {}", buf.length(), data.len()),
            ));
        }
        out.push(data);
    }
    Ok(out)
}

fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let hex = |c: u8| (c as char).to_digit(16).map(|d| d as u8);
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push(h * 16 + l);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// The bytes of element `i` of an accessor, checked against its view and buffer.
struct AccessorData<'a> {
    data: &'a [u8],
    stride: usize,
    elem: usize,
    count: usize,
}

impl AccessorData<'_> {
    fn get(&self, i: usize) -> &[u8] {
        &self.data[i * self.stride..i * self.stride + self.elem]
    }
}

fn accessor_data<'a>(acc: &gltf::Accessor, buffers: &'a [Vec<u8>], path: &Path) -> Result<AccessorData<'a>> {
    let loc = Location::Element { kind: "accessor", index: acc.index() };
    if acc.sparse().is_some() {
        return Err(MeshError::new(ErrorKind::Unsupported, path, loc, "sparse accessors are not supported")
            .hint("Re-export the glTF without sparse accessors."));
    }
    let view = acc.view().ok_or_else(|| {
        MeshError::new(
            ErrorKind::Unsupported,
            path,
            loc.clone(),
            "the accessor has no buffer view (Draco or another compression extension?)",
        )
        .hint("Re-export the glTF without mesh compression.")
    })?;
    let buffer = buffers
        .get(view.buffer().index())
        .ok_or_else(|| MeshError::new(ErrorKind::Syntax, path, loc.clone(), "the accessor's buffer does not exist"))?;
    let elem = acc.size();
    let stride = view.stride().unwrap_or(elem);
    let start = view.offset().checked_add(acc.offset());
    let span = match acc.count() {
        0 => Some(0),
        n => (n - 1).checked_mul(stride).and_then(|s| s.checked_add(elem)),
    };
    let fits = |end: Option<usize>| end.is_some_and(|e| e <= view.offset() + view.length() && e <= buffer.len());
    let end = start.and_then(|s| span.and_then(|n| s.checked_add(n)));
    if stride < elem || !fits(end) {
        return Err(MeshError::new(
            ErrorKind::Truncated,
            path,
            loc,
            format!(
                "the accessor's {} elements of {elem} bytes (stride {stride}) do not fit in buffer view {} ({} bytes) of a {}-byte buffer",
                acc.count(),
                view.index(),
                view.length(),
                buffer.len()
            ),
        ));
    }
    let start = start.unwrap_or(0);
    Ok(AccessorData { data: &buffer[start..end.unwrap_or(start)], stride, elem, count: acc.count() })
}

#[allow(clippy::too_many_arguments)]
fn read_primitive(
    prim: &gltf::Primitive,
    world: &Mat4,
    buffers: &[Vec<u8>],
    path: &Path,
    mesh: &mut TriMesh,
    skipped_modes: &mut Vec<String>,
    mesh_index: usize,
) -> Result<()> {
    let mode = prim.mode();
    if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
        // Points and lines carry no surface; they are skipped, and reported if nothing else
        // is found.
        skipped_modes.push(format!("mesh {mesh_index} primitive {}: {mode:?}", prim.index()));
        return Ok(());
    }
    let loc = Location::Element { kind: "mesh", index: mesh_index };
    let pos = prim.get(&gltf::Semantic::Positions).ok_or_else(|| {
        MeshError::new(
            ErrorKind::Syntax,
            path,
            loc.clone(),
            format!("primitive {} has no POSITION attribute", prim.index()),
        )
    })?;
    if pos.data_type() != DataType::F32 || pos.dimensions() != Dimensions::Vec3 {
        return Err(MeshError::new(
            ErrorKind::Unsupported,
            path,
            Location::Element { kind: "accessor", index: pos.index() },
            format!("POSITION is {:?} {:?}; only float VEC3 positions are read", pos.data_type(), pos.dimensions()),
        )
        .hint("Re-export the glTF without quantised positions (KHR_mesh_quantization)."));
    }
    let pdata = accessor_data(&pos, buffers, path)?;
    let base = mesh.positions.len();
    super::check_vertex_count(base + pdata.count, path)?;
    for i in 0..pdata.count {
        let b = pdata.get(i);
        let c = |k: usize| f32::from_le_bytes([b[4 * k], b[4 * k + 1], b[4 * k + 2], b[4 * k + 3]]) as f64;
        let p = [c(0), c(1), c(2)];
        let location = Location::Element { kind: "accessor", index: pos.index() };
        if let Some(axis) = p.iter().position(|v| !v.is_finite()) {
            let what = format!("POSITION element {i} of accessor {}", pos.index());
            return Err(crate::limits::coordinate_error(path, location, &what, axis, p[axis]));
        }
        let w = world;
        let q = [
            w[0][0] * p[0] + w[1][0] * p[1] + w[2][0] * p[2] + w[3][0],
            w[0][1] * p[0] + w[1][1] * p[1] + w[2][1] * p[2] + w[3][1],
            w[0][2] * p[0] + w[1][2] * p[1] + w[2][2] * p[2] + w[3][2],
        ];
        if let Some((axis, value)) = crate::limits::out_of_range(&q) {
            let what = format!("POSITION element {i} of accessor {} (after the node transforms)", pos.index());
            return Err(crate::limits::coordinate_error(path, location, &what, axis, value));
        }
        mesh.positions.push(q);
    }

    let indices: Vec<u32> = match prim.indices() {
        None => (0..pdata.count as u32).collect(),
        Some(acc) => {
            let d = accessor_data(&acc, buffers, path)?;
            if acc.dimensions() != Dimensions::Scalar {
                return Err(MeshError::new(
                    ErrorKind::Syntax,
                    path,
                    Location::Element { kind: "accessor", index: acc.index() },
                    "indices must be scalars",
                ));
            }
            let read: fn(&[u8]) -> u32 = match acc.data_type() {
                DataType::U8 => |b| b[0] as u32,
                DataType::U16 => |b| u16::from_le_bytes([b[0], b[1]]) as u32,
                DataType::U32 => |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                other => {
                    return Err(MeshError::new(
                        ErrorKind::Syntax,
                        path,
                        Location::Element { kind: "accessor", index: acc.index() },
                        format!("indices of type {other:?}; glTF allows only unsigned byte, short or int"),
                    ))
                }
            };
            let mut out = Vec::with_capacity(d.count);
            for i in 0..d.count {
                let v = read(d.get(i));
                if v as usize >= pdata.count {
                    return Err(MeshError::new(
                        ErrorKind::IndexOutOfRange,
                        path,
                        Location::Element { kind: "accessor", index: acc.index() },
                        format!(
                            "index {i} of accessor {} is {v} but the primitive has {} vertices",
                            acc.index(),
                            pdata.count
                        ),
                    ));
                }
                out.push(v);
            }
            out
        }
    };
    let flip = det3(world) < 0.0;
    let mut push = |a: u32, b: u32, c: u32| {
        let (a, b, c) = (a + base as u32, b + base as u32, c + base as u32);
        mesh.triangles.push(if flip { [a, c, b] } else { [a, b, c] });
    };
    let mut local = Vec::new();
    match mode {
        Mode::Triangles => local.extend(indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]])),
        Mode::TriangleStrip => super::strip(&indices, &mut local),
        Mode::TriangleFan => super::fan(&indices, &mut local),
        _ => {}
    }
    local.into_iter().for_each(|[a, b, c]| push(a, b, c));
    Ok(())
}
