//! Wavefront OBJ through `tobj`, with the checks tobj leaves out.
//!
//! tobj parses and triangulates; it accepts empty files, garbage and NaN coordinates, and
//! its errors carry no line number. After it, this module checks finiteness, the
//! representable range and emptiness, and on any problem scans the text once more to name
//! the offending line.

use std::path::Path;

use super::text;
use crate::error::{ErrorKind, Location, MeshError, Result};
use crate::TriMesh;

pub(crate) fn read(bytes: &[u8], path: &Path) -> Result<TriMesh> {
    let joined = prepare_text(bytes);
    let bytes: &[u8] = &joined;
    let options = tobj::LoadOptions { single_index: false, triangulate: true, ignore_points: true, ignore_lines: true };
    let mut reader = std::io::BufReader::new(bytes);
    // Materials are irrelevant to geometry: a missing .mtl must not fail the load.
    let loaded = tobj::load_obj_buf(&mut reader, &options, |_| Err(tobj::LoadError::OpenFileFailed));
    let (models, _materials) = match loaded {
        Ok(ok) => ok,
        Err(e) => return Err(locate(bytes, path, &e.to_string())),
    };

    let mut mesh = TriMesh::default();
    for model in &models {
        let m = &model.mesh;
        let base = mesh.positions.len();
        super::check_vertex_count(base + m.positions.len() / 3, path)?;
        for p in m.positions.chunks_exact(3) {
            mesh.positions.push([p[0], p[1], p[2]]);
        }
        // With `triangulate`, tobj emits triangles only; any arity other than 3 would be a
        // tobj bug, so check rather than trust it.
        if m.indices.len() % 3 != 0 {
            return Err(MeshError::new(
                ErrorKind::Syntax,
                path,
                Location::File,
                format!("object {:?} did not triangulate into whole triangles", model.name),
            ));
        }
        for t in m.indices.chunks_exact(3) {
            mesh.triangles.push([t[0] + base as u32, t[1] + base as u32, t[2] + base as u32]);
        }
    }
    if mesh.positions.iter().any(|p| crate::limits::out_of_range(p).is_some()) {
        // The scan names the line: parse_point checks finiteness and the range.
        return Err(locate(bytes, path, "a vertex coordinate is NaN, infinite or beyond ±1e30"));
    }
    if mesh.triangles.is_empty() {
        // tobj drops faces with fewer than three corners silently: name such a line if
        // there is one, since it is the likely reason for the empty result.
        let located = locate(bytes, path, "no face");
        if located.location != Location::File {
            return Err(located);
        }
        let n = text_vertex_count(bytes);
        return Err(MeshError::new(
            ErrorKind::Empty,
            path,
            Location::File,
            format!("the file holds no face (it has {n} `v` lines), so it is not an OBJ mesh"),
        ));
    }
    Ok(mesh)
}

/// The text tobj is given, line for line the file's (so error messages keep their line
/// numbers):
/// - The OBJ format lets a line go on after a backslash at its end (trimesh's
///   `wallhole.obj` splits long faces so, with CRLF endings); tobj reads each physical line
///   on its own and would take the backslash for a corner. Continued lines are joined into
///   their first, and the lines taken out come back as empty lines after it (an error in a
///   joined line names its first line). Comment lines are left alone: a path ending in a
///   backslash must not swallow the next line.
/// - `mtllib` and `usemtl` lines become empty: materials are irrelevant to the geometry,
///   and tobj refuses a `usemtl` without a name (the same file, written by Rhino).
///
/// Borrowed when there is nothing to change.
fn prepare_text(bytes: &[u8]) -> std::borrow::Cow<'_, [u8]> {
    let body = |l: &[u8]| -> usize { l.len() - usize::from(l.ends_with(b"\r")) };
    let comment = |l: &[u8]| l.trim_ascii_start().starts_with(b"#");
    let material = |l: &[u8]| {
        let t = l.trim_ascii_start();
        (t.starts_with(b"usemtl") || t.starts_with(b"mtllib")) && t.get(6).is_none_or(|c| c.is_ascii_whitespace())
    };
    let continued = |l: &[u8]| !comment(l) && l[..body(l)].ends_with(b"\\");
    if !bytes.split(|&b| b == b'\n').any(|l| material(l) || continued(l)) {
        return std::borrow::Cow::Borrowed(bytes);
    }
    let lines: Vec<&[u8]> = bytes.split(|&b| b == b'\n').collect();
    let mut out: Vec<u8> = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < lines.len() {
        if i > 0 {
            out.push(b'\n');
        }
        let mut taken = 0;
        if material(lines[i]) {
            // an empty line
        } else {
            while continued(lines[i]) && i + 1 < lines.len() {
                let l = lines[i];
                out.extend_from_slice(&l[..body(l) - 1]);
                out.push(b' ');
                i += 1;
                taken += 1;
            }
            out.extend_from_slice(lines[i]);
        }
        out.extend(std::iter::repeat_n(b'\n', taken));
        i += 1;
    }
    std::borrow::Cow::Owned(out)
}

fn text_vertex_count(bytes: &[u8]) -> usize {
    bytes.split(|&b| b == b'\n').filter(|l| l.starts_with(b"v ") || l.starts_with(b"v\t")).count()
}

/// Find the first line that explains a failure reported by tobj (or by the checks after
/// it), and build the error for it. Falls back to the whole file with tobj's message.
fn locate(bytes: &[u8], path: &Path, what: &str) -> MeshError {
    let lines = match text::lines(bytes, path) {
        Ok(lines) => lines,
        Err(e) => return e,
    };
    let mut num_positions = 0usize;
    for (n, line) in lines {
        let mut toks = line.split_whitespace();
        match toks.next() {
            Some("v") => {
                if let Err(e) = text::parse_point(&mut toks, path, n) {
                    return e;
                }
                num_positions += 1;
            }
            Some("f") => {
                let corners: Vec<&str> = toks.collect();
                if corners.len() < 3 {
                    return MeshError::new(
                        ErrorKind::Syntax,
                        path,
                        Location::Line(n),
                        format!("a face needs at least 3 vertices, this one has {}", corners.len()),
                    );
                }
                for c in corners {
                    let idx = c.split('/').next().unwrap_or("");
                    let Ok(i) = idx.parse::<i64>() else {
                        return MeshError::new(
                            ErrorKind::Syntax,
                            path,
                            Location::Line(n),
                            format!("face corner {c:?} does not start with a vertex number"),
                        );
                    };
                    let resolved = if i > 0 { i - 1 } else { num_positions as i64 + i };
                    if i == 0 || resolved < 0 || resolved >= num_positions as i64 {
                        return MeshError::new(
                            ErrorKind::IndexOutOfRange,
                            path,
                            Location::Line(n),
                            format!(
                                "face corner {c:?} refers to vertex {i}, but only {num_positions} vertices are defined before this line"
                            ),
                        );
                    }
                }
            }
            _ => {}
        }
    }
    MeshError::new(ErrorKind::Syntax, path, Location::File, format!("the OBJ parser failed: {what}"))
}
