//! Output checks made before any long work: which format a path names, and whether its
//! folder can take the file.
//!
//! Every command that writes a mesh calls [`OutputFormat::from_path`] and
//! [`check_output_location`] while parsing its arguments, so a typo in `-o` fails in
//! milliseconds rather than after a training run.

use std::path::Path;

use crate::error::{ErrorKind, Location, MeshError};

/// The mesh formats this program writes, by output extension (case-insensitive).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutputFormat {
    /// `.glb`: binary glTF 2.0, float32 positions.
    Glb,
    /// `.gltf`: glTF 2.0 JSON and a `.bin` beside it with the same stem, float32 positions.
    Gltf,
    /// `.obj`: Wavefront OBJ, f64 coordinates in shortest round-trip decimal (lossless).
    Obj,
    /// `.ply`: binary little-endian PLY, f64 coordinates (lossless).
    Ply,
}

impl OutputFormat {
    /// Every format, in the order messages list them.
    pub const ALL: [OutputFormat; 4] = [OutputFormat::Glb, OutputFormat::Gltf, OutputFormat::Obj, OutputFormat::Ply];

    /// The extension, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            OutputFormat::Glb => "glb",
            OutputFormat::Gltf => "gltf",
            OutputFormat::Obj => "obj",
            OutputFormat::Ply => "ply",
        }
    }

    /// glTF stores positions as float32 (see [`crate::check_f32_resolution`]); OBJ and PLY
    /// as written here are lossless.
    pub fn stores_f32(self) -> bool {
        matches!(self, OutputFormat::Glb | OutputFormat::Gltf)
    }

    /// GLB or glTF: the formats that hold a scene of several meshes with colours
    /// ([`crate::write_gltf`]).
    pub fn is_gltf(self) -> bool {
        self.stores_f32()
    }

    /// The format `path`'s extension names.
    ///
    /// # Errors
    /// [`ErrorKind::UnknownFormat`] naming `path`, with a hint listing `.glb, .gltf, .obj,
    /// .ply`.
    ///
    /// ```
    /// use mesh_io::OutputFormat;
    /// assert_eq!(OutputFormat::from_path("out/crust.GLB".as_ref()).unwrap(), OutputFormat::Glb);
    /// let e = OutputFormat::from_path("crust.stl".as_ref()).unwrap_err();
    /// assert!(e.to_string().contains(".glb, .gltf, .obj or .ply"));
    /// ```
    pub fn from_path(path: &Path) -> Result<OutputFormat, MeshError> {
        Self::from_path_in(path, &Self::ALL)
    }

    /// As [`Self::from_path`], accepting only the formats in `allowed` (for example
    /// `&[OutputFormat::Glb, OutputFormat::Gltf]` for an output with colours); the error
    /// lists those.
    pub fn from_path_in(path: &Path, allowed: &[OutputFormat]) -> Result<OutputFormat, MeshError> {
        let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        if let Some(f) = allowed.iter().copied().find(|f| ext.as_deref() == Some(f.extension())) {
            return Ok(f);
        }
        let names: Vec<String> = allowed.iter().map(|f| format!(".{}", f.extension())).collect();
        let list = match names.split_last() {
            Some((last, [])) => last.clone(),
            Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
            None => "nothing".to_string(),
        };
        let found = match &ext {
            Some(e) => format!("ends in .{e}"),
            None => "has no extension".to_string(),
        };
        Err(MeshError::new(
            ErrorKind::UnknownFormat,
            path,
            Location::File,
            format!("the output {found}, which names no format this program writes here"),
        )
        .hint(format!("End the output name in {list}.")))
    }
}

/// Check, before long work, that `path` can be written: its folder exists, is a folder
/// and is writable (a temporary file is created there, as [`crate::atomic_write`] does,
/// and removed again), and `path` itself is not a folder. Nothing is left behind.
///
/// A write can still fail later (a full disk, a folder removed meanwhile); the writers
/// report that.
///
/// # Errors
/// [`ErrorKind::Write`] naming `path`, saying which of the above fails and how to fix it.
pub fn check_output_location(path: &Path) -> Result<(), MeshError> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let fail = |msg: String, hint: String| MeshError::new(ErrorKind::Write, path, Location::File, msg).hint(hint);
    if path.is_dir() {
        return Err(fail("the output is a folder".into(), "Give a file name, such as out.glb.".into()));
    }
    match std::fs::metadata(dir) {
        Err(_) => {
            return Err(fail(
                format!("the output folder {} does not exist", dir.display()),
                format!("Create it first (mkdir -p {}) or choose another output path.", dir.display()),
            ))
        }
        Ok(m) if !m.is_dir() => {
            return Err(fail(format!("{} is not a folder", dir.display()), "Choose another output path.".into()))
        }
        Ok(_) => {}
    }
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let probe = tempfile::Builder::new().prefix(&format!(".{name}.")).suffix(".tmp").tempfile_in(dir);
    match probe {
        // Dropping the NamedTempFile removes it.
        Ok(tmp) => tmp.close().map_err(|e| MeshError::write(path, e)),
        Err(e) => Err(fail(
            format!("cannot create a file in the output folder {} ({e})", dir.display()),
            "Check that the folder is writable, or choose another output path.".into(),
        )),
    }
}
