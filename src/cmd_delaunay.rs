//! `voronoi-fit delaunay POINTS.npy -o TETS.npy [--validate] [--timings]`: the exact 3D
//! Delaunay tetrahedralization of a point set (crate `delaunay3`).

use std::path::PathBuf;
use std::time::Instant;

use crate::arrays::{read_points_npy, rows_array, write_npy};
use crate::cli_error::{CliError, InFile};
use delaunay3::Delaunay3;

#[derive(clap::Args)]
pub struct Args {
    /// Points: a .npy array of shape (n, 3), float64 or float32, any frame; every
    /// coordinate finite. Coincident points are merged.
    pub points: PathBuf,
    /// Output .npy: the finite tetrahedra, shape (m, 4) uint32, indices into the input
    /// points (a merged duplicate is represented by its first input index), each
    /// positively oriented: det[b − a, c − a, d − a] > 0.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Check the result completely (adjacency, orientation, empty spheres, hull) before
    /// writing it.
    #[arg(long)]
    pub validate: bool,
    /// Print the triangulation time (seconds, excluding file I/O) and counts as one JSON
    /// line on stderr.
    #[arg(long)]
    pub timings: bool,
}

pub fn run(args: Args) -> Result<(), CliError> {
    if args.output.extension().is_none_or(|e| !e.eq_ignore_ascii_case("npy")) {
        return Err(CliError::input(format!("{}: the output must be a .npy file.", args.output.display())));
    }
    let points = read_points_npy(&args.points)?;
    let t0 = Instant::now();
    let dt = Delaunay3::new(&points).in_file(&args.points)?;
    let build_s = t0.elapsed().as_secs_f64();
    let mut validate_s = None;
    if args.validate {
        let t1 = Instant::now();
        dt.validate().map_err(|e| {
            CliError::failure(format!(
                "{}: internal error, please report it with the input file: {e}",
                args.points.display()
            ))
        })?;
        validate_s = Some(t1.elapsed().as_secs_f64());
    }
    let tets = dt.finite_tets_input_indices();
    if args.timings {
        eprintln!(
            "{{\"num_points\": {}, \"num_vertices\": {}, \"num_finite_tets\": {}, \"delaunay_seconds\": {build_s:.6}, \"validate_seconds\": {}}}",
            points.len(),
            dt.num_vertices(),
            tets.len(),
            validate_s.map_or("null".to_string(), |s| format!("{s:.6}"))
        );
    }
    write_npy(&args.output, &rows_array(&tets))
}
