//! Welding of exactly coincident positions.
//!
//! tobj's merging option needs a nightly feature, and STL stores every triangle's corners
//! separately, so every reader's output goes through here.

use std::collections::HashMap;

use crate::TriMesh;

/// Merge vertices whose coordinates are bitwise equal (with -0.0 taken as 0.0), keeping
/// the first occurrence's index order. Triangles are kept as they are, even when welding
/// makes them degenerate: the topology report counts those.
///
/// # Complexity
/// O(V + F) expected time (hashing).
pub fn weld_exact(mesh: &TriMesh) -> TriMesh {
    let key = |p: &[f64; 3]| p.map(|c| if c == 0.0 { 0u64 } else { c.to_bits() });
    let mut map: HashMap<[u64; 3], u32> = HashMap::with_capacity(mesh.positions.len());
    let mut remap = Vec::with_capacity(mesh.positions.len());
    let mut positions = Vec::with_capacity(mesh.positions.len());
    for p in &mesh.positions {
        let next = positions.len() as u32;
        let id = *map.entry(key(p)).or_insert_with(|| {
            positions.push(p.map(|c| if c == 0.0 { 0.0 } else { c }));
            next
        });
        remap.push(id);
    }
    let triangles = mesh.triangles.iter().map(|t| t.map(|i| remap[i as usize])).collect();
    TriMesh { positions, triangles }
}
