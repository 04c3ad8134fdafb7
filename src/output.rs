//! Standard output that survives a closed pipe: `voronoi-fit info MESH | head` must not
//! panic when `head` exits (println! panics on EPIPE).

use std::io::Write;

/// Write one line to stdout; exit quietly (code 0) if the reader has gone away, with
/// code 1 on any other write error.
pub fn write_line(args: std::fmt::Arguments) {
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_fmt(args).and_then(|_| out.write_all(b"\n")).and_then(|_| out.flush()) {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!("error: cannot write to standard output ({e})");
        std::process::exit(1);
    }
}

/// `println!` that handles a closed pipe (see [`write_line`]).
macro_rules! out {
    ($($t:tt)*) => { $crate::output::write_line(format_args!($($t)*)) };
}
pub(crate) use out;

/// The help of `--normals`, shared by `fit`, `crust` and `convert` (docs/viewer.md, *How the GLB shades
/// result*). A constant rather than a flattened argument struct: the main job's arguments
/// are themselves flattened, optionally, into the top-level parser, and clap does not see
/// a nested flattened group's arguments there (`voronoi-fit MESH --normals crease` was
/// then taken for no mesh at all).
pub const NORMALS_HELP: &str =
    "Normals in a glTF output: `flat` (none: viewers shade each triangle flat; every vertex \
    shared, so watertight in any reader), `smooth` (one area-weighted normal per vertex: smooth shapes shade smooth, \
    sharp edges blotchy) or `crease[:DEG]` (smooth except across edges sharper than DEG, 40 by default; a vertex on \
    such an edge is written once per side, which readers that do not weld see as seams). OBJ and PLY carry no normals";
