//! OFF (Object File Format), ASCII: `OFF`, `COFF`, `NOFF`, `CNOFF` headers.
//!
//! Written here: no maintained crate reads OFF, and the format is a few lines. Extra
//! per-vertex values (colours, normals) and per-face colours are skipped.

use std::path::Path;

use super::text;
use crate::error::{ErrorKind, Location, MeshError, Result};
use crate::TriMesh;

pub(crate) fn read(bytes: &[u8], path: &Path) -> Result<TriMesh> {
    let lines = text::lines(bytes, path)?;
    // Comments start with '#'; blank lines are skipped.
    let mut body = lines.iter().filter_map(|(n, l)| {
        let l = l.split('#').next().unwrap_or("").trim();
        (!l.is_empty()).then_some((*n, l))
    });
    let Some((hn, header)) = body.next() else {
        return Err(MeshError::new(ErrorKind::Empty, path, Location::File, "the file holds no data"));
    };
    let mut toks = header.split_whitespace();
    let magic = toks.next().unwrap_or("");
    if !magic.ends_with("OFF") || magic.len() > 5 {
        return Err(MeshError::new(ErrorKind::Syntax, path, Location::Line(hn), "the file does not start with `OFF`"));
    }
    if magic.contains('4') || magic.starts_with("ST") || toks.clone().next() == Some("BINARY") {
        return Err(MeshError::new(
            ErrorKind::Unsupported,
            path,
            Location::Line(hn),
            format!("the OFF variant {header:?} is not supported (only 3D ASCII OFF)"),
        ));
    }
    // The counts may follow the keyword on the same line or stand on the next one.
    let (cn, counts): (usize, Vec<&str>) = match toks.clone().next() {
        Some(_) => (hn, toks.collect()),
        None => match body.next() {
            Some((n, l)) => (n, l.split_whitespace().collect()),
            None => {
                return Err(MeshError::new(
                    ErrorKind::Truncated,
                    path,
                    Location::Line(hn),
                    "the vertex and face counts are missing",
                ))
            }
        },
    };
    let mut ct = counts.iter().copied();
    let num_vertices = text::parse_usize(ct.next(), path, cn, "the vertex count")?;
    let num_faces = text::parse_usize(ct.next(), path, cn, "the face count")?;
    // Each vertex and face needs a line of at least 2 bytes: refuse impossible counts
    // before allocating.
    if num_vertices.saturating_add(num_faces) > bytes.len() / 2 {
        return Err(MeshError::new(
            ErrorKind::Truncated,
            path,
            Location::Line(cn),
            format!("the header announces {num_vertices} vertices and {num_faces} faces, more than the file's {} bytes can hold", bytes.len()),
        ));
    }
    super::check_vertex_count(num_vertices, path)?;
    let mut mesh = TriMesh { positions: Vec::with_capacity(num_vertices), triangles: Vec::with_capacity(num_faces) };
    let truncated = |what: &str, i: usize| {
        MeshError::new(
            ErrorKind::Truncated,
            path,
            Location::Element { kind: if what == "vertex" { "vertex" } else { "face" }, index: i },
            format!("the file ends before {what} {i} of {}", if what == "vertex" { num_vertices } else { num_faces }),
        )
    };
    for i in 0..num_vertices {
        let (n, l) = body.next().ok_or_else(|| truncated("vertex", i))?;
        mesh.positions.push(text::parse_point(&mut l.split_whitespace(), path, n)?);
    }
    let mut poly = Vec::new();
    for i in 0..num_faces {
        let (n, l) = body.next().ok_or_else(|| truncated("face", i))?;
        let mut t = l.split_whitespace();
        let k = text::parse_usize(t.next(), path, n, "the face's vertex count")?;
        poly.clear();
        for _ in 0..k {
            let v = text::parse_usize(t.next(), path, n, "a vertex index")?;
            if v >= num_vertices {
                return Err(MeshError::new(
                    ErrorKind::IndexOutOfRange,
                    path,
                    Location::Line(n),
                    format!("face {i} refers to vertex {v} but the file has {num_vertices} vertices"),
                ));
            }
            poly.push(v as u32);
        }
        if k < 3 {
            return Err(MeshError::new(
                ErrorKind::Syntax,
                path,
                Location::Line(n),
                format!("face {i} has {k} vertices; a face needs at least 3"),
            ));
        }
        super::fan(&poly, &mut mesh.triangles);
    }
    Ok(mesh)
}
