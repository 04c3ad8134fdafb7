//! STL, binary and ASCII.
//!
//! Written here rather than with a crate: the STL crates on crates.io (stl_io, nom_stl)
//! either panic on truncated input or report no position, and the format is small.
//! Binary is recognised by its exact size (84 + 50 × count bytes), which is reliable even
//! when the 80-byte header starts with `solid` as many exporters write.

use std::path::Path;

use super::text;
use crate::error::{ErrorKind, Location, MeshError, Result};
use crate::TriMesh;

pub(crate) fn read(bytes: &[u8], path: &Path) -> Result<TriMesh> {
    if bytes.len() >= 84 {
        let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        if 84 + 50 * count == bytes.len() as u64 {
            return read_binary(bytes, count as usize, path);
        }
    }
    let starts_solid = bytes.iter().skip_while(|b| b.is_ascii_whitespace()).take(5).eq(b"solid".iter());
    if starts_solid && std::str::from_utf8(&bytes[..bytes.len().min(4096)]).is_ok_and(|s| s.contains("facet")) {
        return read_ascii(bytes, path);
    }
    if starts_solid && bytes.len() < 84 {
        return read_ascii(bytes, path);
    }
    if bytes.len() >= 84 {
        let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        let want = 84 + 50 * count;
        let kind = if (bytes.len() as u64) < want { ErrorKind::Truncated } else { ErrorKind::Syntax };
        return Err(MeshError::new(
            kind,
            path,
            Location::Byte(80),
            format!(
                "binary STL header announces {count} triangles ({want} bytes) but the file has {} bytes",
                bytes.len()
            ),
        ));
    }
    Err(MeshError::new(
        ErrorKind::Truncated,
        path,
        Location::File,
        format!("the file has {} bytes: too short for a binary STL (84-byte header) and not ASCII STL", bytes.len()),
    ))
}

fn read_binary(bytes: &[u8], count: usize, path: &Path) -> Result<TriMesh> {
    super::check_vertex_count(count.saturating_mul(3), path)?;
    let mut mesh = TriMesh { positions: Vec::with_capacity(count * 3), triangles: Vec::with_capacity(count) };
    for (t, rec) in bytes[84..].chunks_exact(50).enumerate() {
        let f = |k: usize| f32::from_le_bytes([rec[k], rec[k + 1], rec[k + 2], rec[k + 3]]) as f64;
        let base = mesh.positions.len() as u32;
        for c in 0..3 {
            let o = 12 + 12 * c;
            let p = [f(o), f(o + 4), f(o + 8)];
            if let Some((axis, value)) = crate::limits::out_of_range(&p) {
                let what = format!("corner {c} of triangle {t} (byte {})", 84 + 50 * t + o + 4 * axis);
                let location = Location::Element { kind: "triangle", index: t };
                return Err(crate::limits::coordinate_error(path, location, &what, axis, value));
            }
            mesh.positions.push(p);
        }
        mesh.triangles.push([base, base + 1, base + 2]);
    }
    Ok(mesh)
}

fn read_ascii(bytes: &[u8], path: &Path) -> Result<TriMesh> {
    let mut mesh = TriMesh::default();
    let mut corners: Vec<[f64; 3]> = Vec::with_capacity(3);
    let mut in_loop = false;
    let mut loop_line = 0;
    for (n, line) in text::lines(bytes, path)? {
        let mut toks = line.split_whitespace();
        let Some(keyword) = toks.next() else { continue };
        match keyword {
            "solid" | "endsolid" | "facet" | "endfacet" => {}
            "outer" => {
                if in_loop {
                    return Err(syntax(path, n, "`outer loop` inside another loop (missing `endloop`?)"));
                }
                in_loop = true;
                loop_line = n;
                corners.clear();
            }
            "vertex" => {
                if !in_loop {
                    return Err(syntax(path, n, "`vertex` outside an `outer loop`"));
                }
                corners.push(text::parse_point(&mut toks, path, n)?);
            }
            "endloop" => {
                if !in_loop {
                    return Err(syntax(path, n, "`endloop` without `outer loop`"));
                }
                if corners.len() != 3 {
                    return Err(syntax(
                        path,
                        loop_line,
                        &format!("a facet needs exactly 3 vertices, this loop has {}", corners.len()),
                    ));
                }
                let base = mesh.positions.len() as u32;
                mesh.positions.extend_from_slice(&corners);
                mesh.triangles.push([base, base + 1, base + 2]);
                super::check_vertex_count(mesh.positions.len(), path)?;
                in_loop = false;
            }
            other => {
                return Err(syntax(
                    path,
                    n,
                    &format!("unexpected {other:?}; ASCII STL lines start with solid, facet, outer, vertex, endloop, endfacet or endsolid"),
                ))
            }
        }
    }
    if in_loop {
        return Err(MeshError::new(
            ErrorKind::Truncated,
            path,
            Location::Line(loop_line),
            "the loop started here is never closed (the file ends early)",
        ));
    }
    Ok(mesh)
}

fn syntax(path: &Path, line: usize, msg: &str) -> MeshError {
    MeshError::new(ErrorKind::Syntax, path, Location::Line(line), msg)
}
