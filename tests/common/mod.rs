//! Helpers shared by the CLI test files.
#![allow(dead_code)] // each test file uses its own subset

use std::path::PathBuf;
use std::process::Command;

pub fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_voronoi-fit"))
}

pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

pub fn shared_meshes() -> Vec<PathBuf> {
    let dir =
        std::env::var_os("VF_SHARED_MESHES").map(PathBuf::from).unwrap_or_else(|| root().join("../shared/meshes"));
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: the shared test meshes must sit beside the repository ({e})", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| mesh_io::Format::from_extension(p).is_some())
        .collect();
    v.sort();
    assert!(v.len() >= 8);
    v
}
