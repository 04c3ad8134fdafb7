//! Line-oriented helpers shared by the text readers (ASCII STL, ASCII PLY, OFF, OBJ
//! error location).

use std::path::Path;

use crate::error::{ErrorKind, Location, MeshError, Result};

/// Split `bytes` into `(1-based line number, line)` pairs, without line terminators.
/// Fails on the first line that is not UTF-8, naming it.
pub(crate) fn lines<'a>(bytes: &'a [u8], path: &Path) -> Result<Vec<(usize, &'a str)>> {
    let mut out = Vec::new();
    for (i, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
        let line = std::str::from_utf8(raw).map_err(|_| {
            MeshError::new(
                ErrorKind::Syntax,
                path,
                Location::Line(i + 1),
                "the line is not text (invalid UTF-8); is this a binary file with a text extension?",
            )
        })?;
        out.push((i + 1, line));
    }
    Ok(out)
}

/// Parse one coordinate token, naming the line and what was expected on failure.
pub(crate) fn parse_f64(tok: Option<&str>, path: &Path, line: usize, what: &str) -> Result<f64> {
    let tok = tok.ok_or_else(|| {
        MeshError::new(
            ErrorKind::Syntax,
            path,
            Location::Line(line),
            format!("expected {what}, found the end of the line"),
        )
    })?;
    let v: f64 = tok.parse().map_err(|_| {
        MeshError::new(ErrorKind::Syntax, path, Location::Line(line), format!("expected {what}, found {tok:?}"))
    })?;
    if !v.is_finite() {
        // A 400-digit overflow prints as `inf`, not as itself.
        let shown = if tok.len() <= 24 { format!("{tok:?}") } else { crate::limits::short(v) };
        return Err(MeshError::new(
            ErrorKind::NonFinite,
            path,
            Location::Line(line),
            format!("{what} is {shown}, not a finite number"),
        ));
    }
    Ok(v)
}

/// Parse a non-negative integer token (counts, indices).
pub(crate) fn parse_usize(tok: Option<&str>, path: &Path, line: usize, what: &str) -> Result<usize> {
    let tok = tok.ok_or_else(|| {
        MeshError::new(
            ErrorKind::Syntax,
            path,
            Location::Line(line),
            format!("expected {what}, found the end of the line"),
        )
    })?;
    tok.parse().map_err(|_| {
        MeshError::new(
            ErrorKind::Syntax,
            path,
            Location::Line(line),
            format!("expected {what} (a non-negative whole number), found {tok:?}"),
        )
    })
}

/// Three coordinates from a token iterator, each finite and within the representable
/// range of [`crate::limits`].
pub(crate) fn parse_point<'a>(toks: &mut impl Iterator<Item = &'a str>, path: &Path, line: usize) -> Result<[f64; 3]> {
    let p = [
        parse_f64(toks.next(), path, line, "an x coordinate")?,
        parse_f64(toks.next(), path, line, "a y coordinate")?,
        parse_f64(toks.next(), path, line, "a z coordinate")?,
    ];
    if let Some((axis, value)) = crate::limits::out_of_range(&p) {
        return Err(crate::limits::coordinate_error(path, Location::Line(line), "the vertex", axis, value));
    }
    Ok(p)
}
