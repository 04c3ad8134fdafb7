//! Reading meshes: one file per format, one entry point, [`read_mesh`].
//!
//! Every reader reports problems with the file name and a line (text formats) or an element
//! index / byte offset (binary formats). The shared checks after parsing (finite
//! coordinates within the representable range of [`crate::limits`], indices in range, at
//! least one triangle) run in [`finish`] so that no format can skip them; readers also
//! check as they go, to name the line.

mod gltf;
mod obj;
mod off;
mod ply;
mod stl;
pub(crate) mod text;

use std::path::Path;

use crate::error::{ErrorKind, Location, MeshError, Result};
use crate::weld::weld_exact;
use crate::TriMesh;

/// The input formats [`read_mesh`] understands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Wavefront OBJ (tobj).
    Obj,
    /// STL, ASCII or binary.
    Stl,
    /// PLY, ASCII or binary (either byte order).
    Ply,
    /// OFF (Object File Format).
    Off,
    /// glTF 2.0, JSON (`.gltf`) or binary (`.glb`): the reader tells them apart by content.
    Gltf,
}

impl Format {
    /// The format a file extension names (case-insensitive), if any.
    pub fn from_extension(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "obj" => Format::Obj,
            "stl" => Format::Stl,
            "ply" => Format::Ply,
            "off" => Format::Off,
            "gltf" | "glb" => Format::Gltf,
            _ => return None,
        })
    }

    /// The format the first bytes of a file announce, if they are distinctive.
    pub fn sniff(bytes: &[u8]) -> Option<Format> {
        let head = &bytes[..bytes.len().min(16)];
        if head.starts_with(b"glTF") {
            return Some(Format::Gltf);
        }
        if head.starts_with(b"ply\n") || head.starts_with(b"ply\r") {
            return Some(Format::Ply);
        }
        let trimmed = trim_ascii_start(head);
        if trimmed.starts_with(b"OFF") || trimmed.starts_with(b"COFF") || trimmed.starts_with(b"NOFF") {
            return Some(Format::Off);
        }
        if trimmed.starts_with(b"solid") {
            return Some(Format::Stl);
        }
        None
    }
}

fn trim_ascii_start(b: &[u8]) -> &[u8] {
    let n = b.iter().take_while(|c| c.is_ascii_whitespace()).count();
    &b[n..]
}

/// Read a triangle mesh from `path`, welding exactly coincident positions.
///
/// The format comes from the extension; a file whose first bytes clearly announce another
/// supported format (a `.stl` that is really a PLY, say) is read as what it is.
/// Polygons are triangulated as fans; glTF node transforms are applied.
///
/// # Errors
/// A [`MeshError`] naming the file and the line or element, for unreadable files,
/// unknown formats, syntax errors, truncated binaries, NaN or infinite coordinates,
/// coordinates outside the representable range ([`crate::check_representable`]: beyond
/// ±1e30, or a mesh spanning less than 1e-30), out-of-range indices, unsupported features
/// and meshes without a triangle.
///
/// # Example
/// ```
/// # fn main() -> Result<(), mesh_io::MeshError> {
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("tri.obj");
/// std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
/// let mesh = mesh_io::read_mesh(&path)?;
/// assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
/// # Ok(()) }
/// ```
pub fn read_mesh(path: &Path) -> std::result::Result<TriMesh, MeshError> {
    let bytes = std::fs::read(path).map_err(|e| MeshError::io(path, e))?;
    read_mesh_from_bytes(&bytes, path)
}

/// Like [`read_mesh`] for bytes already in memory; `path` names the file in messages, gives
/// the extension, and is the base for a `.gltf`'s external buffers.
pub fn read_mesh_from_bytes(bytes: &[u8], path: &Path) -> std::result::Result<TriMesh, MeshError> {
    if bytes.is_empty() {
        return Err(MeshError::new(ErrorKind::Empty, path, Location::File, "the file is empty (0 bytes)"));
    }
    let format = match (Format::sniff(bytes), Format::from_extension(path)) {
        (Some(sniffed), _) => sniffed,
        (None, Some(ext)) => ext,
        (None, None) => {
            return Err(MeshError::new(
                ErrorKind::UnknownFormat,
                path,
                Location::File,
                "the extension and the first bytes match no supported mesh format",
            ))
        }
    };
    let raw = match format {
        Format::Obj => obj::read(bytes, path)?,
        Format::Stl => stl::read(bytes, path)?,
        Format::Ply => ply::read(bytes, path)?,
        Format::Off => off::read(bytes, path)?,
        Format::Gltf => gltf::read(bytes, path)?,
    };
    finish(raw, path)
}

/// Shared checks after parsing (finite and representable coordinates, indices in range, at
/// least one triangle), then exact welding.
pub(crate) fn finish(mesh: TriMesh, path: &Path) -> Result<TriMesh> {
    check_contents(&mesh, path)?;
    if mesh.triangles.is_empty() {
        return Err(MeshError::new(
            ErrorKind::Empty,
            path,
            Location::File,
            format!("the file holds no triangle ({} vertices, 0 faces)", mesh.positions.len()),
        ));
    }
    Ok(weld_exact(&mesh))
}

/// Every coordinate finite and within the representable range, every index in range;
/// vertices are named by their index in `mesh.positions` (before welding).
pub(crate) fn check_contents(mesh: &TriMesh, path: &Path) -> Result<()> {
    crate::limits::check_representable(mesh, path)?;
    let n = mesh.positions.len();
    for (f, t) in mesh.triangles.iter().enumerate() {
        if let Some(&bad) = t.iter().find(|&&i| i as usize >= n) {
            return Err(MeshError::new(
                ErrorKind::IndexOutOfRange,
                path,
                Location::Element { kind: "face", index: f },
                format!("face {f} refers to vertex {bad} but the file has {n} vertices"),
            ));
        }
    }
    Ok(())
}

/// Triangulate a polygon given by its vertex ids as a fan around its first vertex.
/// Polygons with fewer than three corners give no triangle.
pub(crate) fn fan(poly: &[u32], out: &mut Vec<[u32; 3]>) {
    for k in 1..poly.len().saturating_sub(1) {
        out.push([poly[0], poly[k], poly[k + 1]]);
    }
}

/// The triangles of one strip: triangle k is (s[k], s[k+1], s[k+2]) with every second one
/// reversed so that all keep the first one's orientation. Triangles with a repeated vertex
/// are the zero-area joints strips use to turn corners, not faces, and are left out.
pub(crate) fn strip(s: &[u32], out: &mut Vec<[u32; 3]>) {
    for (k, w) in s.windows(3).enumerate() {
        let t = if k % 2 == 0 { [w[0], w[1], w[2]] } else { [w[1], w[0], w[2]] };
        if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
            out.push(t);
        }
    }
}

/// Convert a vertex count to u32 or say the mesh is too large.
pub(crate) fn check_vertex_count(n: usize, path: &Path) -> Result<()> {
    if n > u32::MAX as usize {
        return Err(MeshError::new(
            ErrorKind::Unsupported,
            path,
            Location::File,
            format!("the mesh has {n} vertices, more than the 4,294,967,295 that 32-bit indices address"),
        )
        .hint("Split the mesh into parts."));
    }
    Ok(())
}
