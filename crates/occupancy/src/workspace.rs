//! Reusable scratch buffers for the per-query traversals.

/// Traversal stacks reused across queries so hot loops do not allocate.
///
/// One per thread: batch functions create one per rayon task with `for_each_init`.
#[derive(Debug, Default, Clone)]
pub struct Workspace {
    /// Node stack of the winding-number traversals.
    pub(crate) nodes: Vec<u32>,
    /// (node, lane mask) stack of the packet traversal of the fast winding number.
    pub(crate) packets: Vec<(u32, crate::winding::fast::LaneMask)>,
    /// (node, squared box distance) stack of the closest-point traversal.
    pub(crate) nodes_with_bound: Vec<(u32, f64)>,
    /// Number of fast winding queries recomputed exactly because they fell within
    /// `Config::exact_fallback_margin` of the threshold (counts since creation).
    pub num_exact_fallbacks: u64,
    /// Slot of the previous closest triangle: the next closest-point search starts from
    /// it (a tight initial bound for spatially coherent queries; never changes the
    /// distance found). Batch functions reset it at every fixed-size chunk.
    pub(crate) last_slot: Option<u32>,
}

impl Workspace {
    /// Empty workspace with room for typical BVH depths.
    pub fn new() -> Self {
        Workspace {
            nodes: Vec::with_capacity(128),
            packets: Vec::with_capacity(128),
            nodes_with_bound: Vec::with_capacity(128),
            num_exact_fallbacks: 0,
            last_slot: None,
        }
    }
}
