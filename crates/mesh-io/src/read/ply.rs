//! PLY: ASCII, binary little-endian and binary big-endian.
//!
//! Written here rather than with `ply-rs`: that crate has had no release since 2020, panics
//! on several malformed headers, and reports no byte offsets. Every count in the header
//! is checked against the bytes that remain before anything is allocated, so a header
//! announcing billions of elements fails fast instead of exhausting memory.

use std::path::Path;

use crate::error::{ErrorKind, Location, MeshError, Result};
use crate::TriMesh;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }
    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
}

#[derive(Debug)]
enum Property {
    Scalar { name: String, ty: Scalar },
    List { name: String, count: Scalar, item: Scalar },
}

#[derive(Debug)]
struct Element {
    name: String,
    count: usize,
    props: Vec<Property>,
}

#[derive(Clone, Copy, PartialEq)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

pub(crate) fn read(bytes: &[u8], path: &Path) -> Result<TriMesh> {
    let header = parse_header(bytes, path)?;
    let layout = Layout::of(&header.elements, path)?;
    let mut reader: Box<dyn Values + '_> = match header.encoding {
        Encoding::Ascii => Box::new(AsciiValues::new(bytes, header.body_start, header.lines)),
        Encoding::Little | Encoding::Big => {
            Box::new(BinaryValues { bytes, pos: header.body_start, big: header.encoding == Encoding::Big })
        }
    };
    let remaining = bytes.len() - header.body_start.min(bytes.len());
    let mut body = Body { layout, mesh: TriMesh::default(), poly: Vec::new() };
    for (ei, el) in header.elements.iter().enumerate() {
        check_count_fits(el, remaining, path)?;
        if ei == body.layout.vertex {
            super::check_vertex_count(el.count, path)?;
            body.mesh.positions.reserve(el.count);
        }
        for i in 0..el.count {
            body.read_instance(reader.as_mut(), el, ei, i, path)?;
        }
    }
    Ok(body.mesh)
}

/// Where the geometry is among the header's elements and properties.
struct Layout {
    /// Index of the `vertex` element.
    vertex: usize,
    /// Indices of the x, y, z properties within it.
    xyz: [usize; 3],
    /// Index of the `face` (or `tristrips`) element and of its vertex-index list
    /// property, if any.
    face: Option<(usize, usize)>,
    /// The faces are triangle strips (`tristrips`), not polygons.
    strips: bool,
}

impl Layout {
    fn of(elements: &[Element], path: &Path) -> Result<Layout> {
        let (vertex, xyz) = vertex_layout(elements, path)?;
        let (face, strips) = face_layout(elements, path)?;
        if let Some((f, _)) = face.filter(|&(f, _)| f < vertex) {
            return Err(MeshError::new(
                ErrorKind::Unsupported,
                path,
                Location::File,
                format!("the `{}` element comes before the `vertex` element", elements[f].name),
            ));
        }
        Ok(Layout { vertex, xyz, face, strips })
    }
}

/// The `vertex` element and its scalar properties x, y, z.
fn vertex_layout(elements: &[Element], path: &Path) -> Result<(usize, [usize; 3])> {
    let vertex = elements.iter().position(|e| e.name == "vertex").ok_or_else(|| {
        MeshError::new(ErrorKind::Syntax, path, Location::File, "the header declares no `vertex` element")
    })?;
    let mut xyz = [None; 3];
    for (k, p) in elements[vertex].props.iter().enumerate() {
        if let Property::Scalar { name, .. } = p {
            match name.as_str() {
                "x" => xyz[0] = Some(k),
                "y" => xyz[1] = Some(k),
                "z" => xyz[2] = Some(k),
                _ => {}
            }
        }
    }
    let [Some(px), Some(py), Some(pz)] = xyz else {
        return Err(MeshError::new(
            ErrorKind::Syntax,
            path,
            Location::File,
            "the `vertex` element lacks one of the scalar properties x, y, z",
        ));
    };
    Ok((vertex, [px, py, pz]))
}

/// The `face` element and its list property `vertex_indices` (or `vertex_index`), if the
/// file has faces; failing that, the `tristrips` element (Stanford's scans, e.g. igea.ply,
/// store their triangles as strips: one list of vertex ids, -1 between strips), with
/// `true` for strips.
fn face_layout(elements: &[Element], path: &Path) -> Result<(Option<(usize, usize)>, bool)> {
    let (face, strips) = match elements.iter().position(|e| e.name == "face") {
        Some(f) => (f, false),
        None => match elements.iter().position(|e| e.name == "tristrips") {
            Some(f) => (f, true),
            None => return Ok((None, false)),
        },
    };
    let prop = elements[face]
        .props
        .iter()
        .position(|p| matches!(p, Property::List { name, .. } if name == "vertex_indices" || name == "vertex_index"))
        .ok_or_else(|| {
            MeshError::new(
                ErrorKind::Syntax,
                path,
                Location::File,
                format!("the `{}` element has no list property `vertex_indices`", elements[face].name),
            )
        })?;
    Ok((Some((face, prop)), strips))
}

/// Refuse counts the remaining bytes cannot hold (at least one byte per element per
/// property), before allocating for them.
fn check_count_fits(el: &Element, remaining: usize, path: &Path) -> Result<()> {
    let min_bytes = el.count.saturating_mul(el.props.len().max(1));
    if el.count > 0 && min_bytes > remaining {
        return Err(MeshError::new(
            ErrorKind::Truncated,
            path,
            Location::File,
            format!(
                "the header announces {} `{}` elements, more than the {remaining} bytes after the header can hold",
                el.count, el.name
            ),
        ));
    }
    Ok(())
}

/// The mesh being read, with the layout that says which values are geometry.
struct Body {
    layout: Layout,
    mesh: TriMesh,
    /// The current face's vertex ids (reused).
    poly: Vec<u32>,
}

impl Body {
    /// Read instance `i` of element `el` (the `ei`-th), keeping vertices and faces.
    fn read_instance(&mut self, reader: &mut dyn Values, el: &Element, ei: usize, i: usize, path: &Path) -> Result<()> {
        reader.start_element(&el.name, i, path)?;
        let is_vertex = ei == self.layout.vertex;
        let mut p = [0.0; 3];
        for (k, prop) in el.props.iter().enumerate() {
            match prop {
                Property::Scalar { ty, .. } => {
                    let v = reader.scalar(*ty, &el.name, i, path)?;
                    if let Some(axis) = self.layout.xyz.iter().position(|&x| is_vertex && x == k) {
                        p[axis] = v;
                    }
                }
                Property::List { count, item, .. } => {
                    let is_faces = self.layout.face == Some((ei, k));
                    self.read_list(reader, (*count, *item), el, i, is_faces, path)?;
                }
            }
        }
        reader.end_element(&el.name, i, path)?;
        if is_vertex {
            if let Some((axis, value)) = crate::limits::out_of_range(&p) {
                let location = reader.location(&el.name, i);
                return Err(crate::limits::coordinate_error(path, location, &format!("vertex {i}"), axis, value));
            }
            self.mesh.positions.push(p);
        }
        Ok(())
    }

    /// Read one list value; for the faces' vertex indices, check them and add the polygon
    /// as a fan of triangles.
    fn read_list(
        &mut self,
        reader: &mut dyn Values,
        (count, item): (Scalar, Scalar),
        el: &Element,
        i: usize,
        is_faces: bool,
        path: &Path,
    ) -> Result<()> {
        let n = reader.scalar(count, &el.name, i, path)?;
        // A polygon has at most a million corners; a strip may hold a whole mesh (its
        // values are read one by one, so a length the file cannot hold fails as truncated)
        let max_len = if is_faces && self.layout.strips { u32::MAX as f64 } else { 1.0e6 };
        if !(0.0..=max_len).contains(&n) || n.fract() != 0.0 {
            return Err(reader.error(
                &el.name,
                i,
                path,
                &format!("list length {n} is not a whole number between 0 and {max_len}"),
            ));
        }
        self.poly.clear();
        let num_positions = self.mesh.positions.len();
        for _ in 0..n as usize {
            let v = reader.scalar(item, &el.name, i, path)?;
            if !is_faces {
                continue;
            }
            if self.layout.strips && v == -1.0 {
                super::strip(&self.poly, &mut self.mesh.triangles);
                self.poly.clear();
                continue;
            }
            if v < 0.0 || v.fract() != 0.0 || v >= num_positions as f64 {
                return Err(MeshError::new(
                    ErrorKind::IndexOutOfRange,
                    path,
                    reader.location(&el.name, i),
                    format!("{} {i} refers to vertex {v} but the file has {num_positions} vertices", el.name),
                ));
            }
            self.poly.push(v as u32);
        }
        if is_faces && self.layout.strips {
            super::strip(&self.poly, &mut self.mesh.triangles);
        } else if is_faces {
            super::fan(&self.poly, &mut self.mesh.triangles);
        }
        Ok(())
    }
}

/// What the header says: encoding, elements, where the body starts and how many lines the
/// header has.
struct Header {
    encoding: Encoding,
    elements: Vec<Element>,
    body_start: usize,
    lines: usize,
}

fn parse_header(bytes: &[u8], path: &Path) -> Result<Header> {
    let mut pos = 0usize;
    let mut line_no = 0usize;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        let Some(len) = bytes[pos..].iter().position(|&b| b == b'\n') else {
            return Err(MeshError::new(
                ErrorKind::Truncated,
                path,
                Location::Line(line_no + 1),
                "the header never reaches `end_header`",
            ));
        };
        line_no += 1;
        let raw = &bytes[pos..pos + len];
        pos += len + 1;
        let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
        let err = |msg: String| MeshError::new(ErrorKind::Syntax, path, Location::Line(line_no), msg);
        let line = std::str::from_utf8(raw).map_err(|_| err("the header line is not text".into()))?;
        let toks: Vec<&str> = line.split_whitespace().collect();
        match toks.as_slice() {
            ["ply"] if line_no == 1 => {}
            _ if line_no == 1 => return Err(err("the file does not start with `ply`".into())),
            ["format", f, _version] => {
                encoding = Some(match *f {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::Little,
                    "binary_big_endian" => Encoding::Big,
                    other => return Err(err(format!("unknown format {other:?}"))),
                })
            }
            ["comment", ..] | ["obj_info", ..] | [] => {}
            ["element", name, count] => {
                let count = count.parse().map_err(|_| err(format!("element count {count:?} is not a whole number")))?;
                elements.push(Element { name: name.to_string(), count, props: Vec::new() });
            }
            ["property", "list", ct, it, name] => {
                let el = elements.last_mut().ok_or_else(|| err("`property` before any `element`".into()))?;
                let count = Scalar::parse(ct).ok_or_else(|| err(format!("unknown type {ct:?}")))?;
                let item = Scalar::parse(it).ok_or_else(|| err(format!("unknown type {it:?}")))?;
                if matches!(count, Scalar::F32 | Scalar::F64) {
                    return Err(err("a list length must have an integer type".into()));
                }
                el.props.push(Property::List { name: name.to_string(), count, item });
            }
            ["property", ty, name] => {
                let el = elements.last_mut().ok_or_else(|| err("`property` before any `element`".into()))?;
                let ty = Scalar::parse(ty).ok_or_else(|| err(format!("unknown type {ty:?}")))?;
                el.props.push(Property::Scalar { name: name.to_string(), ty });
            }
            ["end_header"] => break,
            _ => return Err(err(format!("unexpected header line {line:?}"))),
        }
    }
    let encoding = encoding
        .ok_or_else(|| MeshError::new(ErrorKind::Syntax, path, Location::File, "the header has no `format` line"))?;
    Ok(Header { encoding, elements, body_start: pos, lines: line_no })
}

/// A source of property values, ASCII or binary.
trait Values {
    fn start_element(&mut self, element: &str, index: usize, path: &Path) -> Result<()>;
    fn scalar(&mut self, ty: Scalar, element: &str, index: usize, path: &Path) -> Result<f64>;
    fn end_element(&mut self, element: &str, index: usize, path: &Path) -> Result<()>;
    fn location(&self, element: &str, index: usize) -> Location;
    fn error(&self, element: &str, index: usize, path: &Path, msg: &str) -> MeshError {
        MeshError::new(ErrorKind::Syntax, path, self.location(element, index), msg)
    }
}

struct BinaryValues<'a> {
    bytes: &'a [u8],
    pos: usize,
    big: bool,
}

impl Values for BinaryValues<'_> {
    fn start_element(&mut self, _: &str, _: usize, _: &Path) -> Result<()> {
        Ok(())
    }
    fn scalar(&mut self, ty: Scalar, element: &str, index: usize, path: &Path) -> Result<f64> {
        let n = ty.size();
        let Some(b) = self.bytes.get(self.pos..self.pos + n) else {
            return Err(MeshError::new(
                ErrorKind::Truncated,
                path,
                Location::Element { kind: element_kind(element), index },
                format!("the file ends at byte {} inside {element} {index}: it is truncated", self.bytes.len()),
            ));
        };
        self.pos += n;
        let mut a = [0u8; 8];
        a[..n].copy_from_slice(b);
        if self.big {
            a[..n].reverse();
        }
        Ok(match ty {
            Scalar::I8 => a[0] as i8 as f64,
            Scalar::U8 => a[0] as f64,
            Scalar::I16 => i16::from_le_bytes([a[0], a[1]]) as f64,
            Scalar::U16 => u16::from_le_bytes([a[0], a[1]]) as f64,
            Scalar::I32 => i32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::U32 => u32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::F32 => f32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::F64 => f64::from_le_bytes(a),
        })
    }
    fn end_element(&mut self, _: &str, _: usize, _: &Path) -> Result<()> {
        Ok(())
    }
    fn location(&self, element: &str, index: usize) -> Location {
        Location::Element { kind: element_kind(element), index }
    }
}

/// Element names as `'static` labels for [`Location::Element`].
fn element_kind(element: &str) -> &'static str {
    match element {
        "vertex" => "vertex",
        "face" => "face",
        "edge" => "edge",
        _ => "element",
    }
}

/// ASCII bodies: one element instance per line, as every PLY writer does.
type NumberedLines<'a> = std::iter::Enumerate<std::slice::Split<'a, u8, fn(&u8) -> bool>>;

struct AsciiValues<'a> {
    lines: NumberedLines<'a>,
    first_line: usize,
    current: Vec<&'a str>,
    next_tok: usize,
    line_no: usize,
}

impl<'a> AsciiValues<'a> {
    fn new(bytes: &'a [u8], body_start: usize, header_lines: usize) -> Self {
        let is_nl: fn(&u8) -> bool = |&b| b == b'\n';
        AsciiValues {
            lines: bytes[body_start.min(bytes.len())..].split(is_nl).enumerate(),
            first_line: header_lines + 1,
            current: Vec::new(),
            next_tok: 0,
            line_no: header_lines,
        }
    }
}

impl Values for AsciiValues<'_> {
    fn start_element(&mut self, element: &str, index: usize, path: &Path) -> Result<()> {
        loop {
            let Some((i, raw)) = self.lines.next() else {
                return Err(MeshError::new(
                    ErrorKind::Truncated,
                    path,
                    Location::Element { kind: element_kind(element), index },
                    format!("the file ends before {element} {index}: it is truncated"),
                ));
            };
            self.line_no = self.first_line + i;
            let line = std::str::from_utf8(raw).map_err(|_| {
                MeshError::new(ErrorKind::Syntax, path, Location::Line(self.line_no), "the line is not text")
            })?;
            self.current = line.split_whitespace().collect();
            self.next_tok = 0;
            if !self.current.is_empty() {
                return Ok(());
            }
        }
    }
    fn scalar(&mut self, ty: Scalar, element: &str, index: usize, path: &Path) -> Result<f64> {
        let Some(tok) = self.current.get(self.next_tok) else {
            return Err(self.error(element, index, path, &format!("{element} {index} has too few values on its line")));
        };
        self.next_tok += 1;
        let v: f64 = tok.parse().map_err(|_| self.error(element, index, path, &format!("{tok:?} is not a number")))?;
        let integral = !matches!(ty, Scalar::F32 | Scalar::F64);
        if integral && v.is_finite() && v.fract() != 0.0 {
            return Err(self.error(element, index, path, &format!("{tok:?} should be a whole number")));
        }
        // A `float` property holds a float32, whatever digits the text has: round as the
        // binary encodings (and numpy, trimesh) do.
        Ok(if ty == Scalar::F32 { v as f32 as f64 } else { v })
    }
    fn end_element(&mut self, element: &str, index: usize, path: &Path) -> Result<()> {
        if self.next_tok != self.current.len() {
            return Err(self.error(
                element,
                index,
                path,
                &format!(
                    "{element} {index} has {} values on its line, the header declares {}",
                    self.current.len(),
                    self.next_tok
                ),
            ));
        }
        Ok(())
    }
    fn location(&self, _: &str, _: usize) -> Location {
        Location::Line(self.line_no)
    }
}
