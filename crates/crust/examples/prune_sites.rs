//! Removes the sites of a sites file that change neither the crust nor the occupancy
//! (`crust::prune`) and prints how many, with the crust's area and volume before and after.
//!
//!     cargo run --release -p crust --example prune_sites -- FILE.sites.npz...

use crust::{Crust, CrustConfig, SitesFile};
use std::time::Instant;

fn main() {
    for path in std::env::args().skip(1) {
        let f = SitesFile::read(std::path::Path::new(&path)).expect("readable sites file");
        let (mut sites, mut inside) = (f.sites.clone(), f.inside.clone());
        let before = Crust::extract(&sites, &inside, &CrustConfig::default()).expect("crust");
        let t = Instant::now();
        let r = crust::prune::prune(&mut sites, &mut inside, 0, 16, &CrustConfig::default()).expect("prune");
        let secs = t.elapsed().as_secs_f64();
        let after = Crust::extract(&sites, &inside, &CrustConfig::default()).expect("crust");
        let m = |c: &Crust| {
            let t = mesh_io::TopologyReport::of(&c.mesh);
            (c.mesh.positions.len(), t.signed_volume)
        };
        println!(
            "{path}: {} sites, removed {} ({:?}) in {secs:.2} s; crust vertices/volume {:?} -> {:?}",
            f.sites.len(),
            r.removed(),
            r.removed_per_round,
            m(&before),
            m(&after)
        );
    }
}
