//! Regenerates the meshes in `assets/` that the project generates itself.
//!
//!     cargo run -p mesh-io --example make_assets -- assets
//!
//! `assets_are_up_to_date` in crates/mesh-io/tests/shapes.rs checks the committed files
//! against this generator.

use std::path::PathBuf;

fn main() -> Result<(), mesh_io::MeshError> {
    let dir = PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| "assets".into()));
    for (name, mesh) in mesh_io::shapes::asset_shapes() {
        mesh_io::write_obj(&dir.join(format!("{name}.obj")), &mesh)?;
        println!("wrote {}", dir.join(format!("{name}.obj")).display());
    }
    Ok(())
}
