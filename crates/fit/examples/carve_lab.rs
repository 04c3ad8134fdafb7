//! Replays the main job's carving (`fit::carve::carve`, the default tolerance, rounds and
//! budget) on sites written before it, so a change to carving can be measured in seconds
//! instead of a whole fit:
//!
//! ```text
//! voronoi-fit MESH --no-carve --no-prune -o /tmp/pre.glb        # writes /tmp/pre.sites.npz
//! cargo run --release -p fit --example carve_lab -- MESH /tmp/pre.sites.npz [K]
//! ```
//!
//! Prints, per extraction, the farthest crust vertex from the input and the input's farthest
//! point from the crust (% of the diagonal), the state kept and the sites inserted.
//! K (default 8,192) sets the budget, K/8 sites, as in the main job.

use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let (Some(mesh_path), Some(sites_path)) = (args.get(1), args.get(2)) else {
        return Err("usage: carve_lab MESH SITES.npz [K]".into());
    };
    let k: usize = args.get(3).map(|s| s.parse()).transpose()?.unwrap_or(fit::DEFAULT_SITES);
    let mesh = fit::data::compact(&mesh_io::read_mesh(Path::new(mesh_path))?);
    let file = crust::SitesFile::read(Path::new(sites_path))?;
    let transform = mesh_io::UnitCubeTransform::of_mesh(&mesh, fit::MARGIN).ok_or("the mesh has no extent")?;
    let unit = transform.mesh_to_unit(&mesh);
    let oracle = occupancy::MeshOracle::from_mesh(&unit, &occupancy::Config::default())?;
    let solid = soft_voronoi::MeshSolid { oracle: &oracle };
    let diagonal = unit.diagonal();
    let (mut sites, mut labels) = (file.sites, file.inside);
    let tolerance = fit::DEFAULT_CARVE * diagonal;
    let r = fit::carve::carve(
        &mut sites,
        &mut labels,
        &oracle,
        &unit,
        &solid,
        &fit::carve::CarveOptions::for_sites(tolerance, k),
    )?;
    let pct = |v: &[f64]| v.iter().map(|f| format!("{:.3}", 100.0 * f / diagonal)).collect::<Vec<_>>().join(" ");
    let kept = r.inserted_per_round.len();
    println!("crust vertex farthest from the input, per extraction (%): {}", pct(&r.farthest_per_round));
    println!("input point farthest from the crust, per extraction (%): {}", pct(&r.input_farthest_per_round));
    println!(
        "kept state {kept} (sites inserted per round {:?}, {} rounds undone): two-sided {:.3}%",
        r.inserted_per_round,
        r.undone_rounds,
        100.0 * r.farthest_per_round[kept].max(r.input_farthest_per_round[kept]) / diagonal
    );
    Ok(())
}
