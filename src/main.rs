//! `voronoi-fit`: the command-line front end. It parses arguments, wires the library
//! crates together and maps errors to exit codes; the work happens in `crates/`.
//!
//! Exit codes: 0 success, 2 bad input or usage, 1 any other failure.

mod arrays;
mod cli_error;
mod cmd_batch;
mod cmd_convert;
mod cmd_crust;
mod cmd_delaunay;
mod cmd_eval;
mod cmd_fit;
mod cmd_info;
mod cmd_mnist;
mod cmd_query;
mod cmd_sample;
mod cmd_study;
mod cmd_view;
mod output;

use clap::{Parser, Subcommand};

use cli_error::CliError;

#[derive(Parser)]
#[command(
    name = "voronoi-fit",
    version,
    about = "Turn a triangle mesh into labelled Voronoi sites and back into a watertight crust",
    long_about = "Turn a triangle mesh into labelled Voronoi sites and back into a watertight crust.\n\n\
                  `voronoi-fit MESH` runs the main job (the same as `voronoi-fit fit MESH`): train the sites, \
                  write MESH-stem.voronoi.glb, .sites.npz and .report.json. The subcommands run single stages.",
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    fit: Option<cmd_fit::Args>,
}

#[derive(Subcommand)]
enum Command {
    /// The main job: fit Voronoi sites to a mesh, write the crust, sites and report.
    Fit(Box<cmd_fit::Args>),
    /// The sphere study: Voronoi sites against OccNet / DeepSDF MLPs, Hausdorff distance
    /// against parameter count (results.csv, plot, table.md).
    Study(cmd_study::Args),
    /// The main job on many meshes: one folder per mesh and summary.csv; a rerun skips what
    /// finished, resumes what stopped and retries what failed.
    Batch(cmd_batch::Args),
    /// The seed's MNIST autoencoder: encoder → Voronoi decoder (128 sites) or OccNet decoder; train, eval, tsne, interpolate.
    Mnist(cmd_mnist::Args),
    /// Print the topology report of a mesh (counts, boundary, manifoldness, genus, volume).
    Info(cmd_info::Args),
    /// Convert a mesh to GLB, glTF, OBJ or PLY (optionally normalised into the unit cube).
    Convert(cmd_convert::Args),
    /// Draw training samples (uniform + near-surface) with winding number, occupancy and
    /// signed distance.
    Sample(cmd_sample::Args),
    /// Winding number, occupancy, signed distance and closest point of given points.
    Query(cmd_query::Args),
    /// Exact 3D Delaunay tetrahedralization of a point set (.npy in, .npy of tets out).
    Delaunay(cmd_delaunay::Args),
    /// Watertight crust (and optionally the convex inside cells) of a sites file.
    Crust(cmd_crust::Args),
    /// Reconstruction metrics of a predicted mesh against a reference: certified and
    /// libigl-compatible Hausdorff, Chamfer, F-score, normal consistency, IoU, validity.
    Eval(cmd_eval::Args),
    /// One self-contained HTML page (works offline) showing the input and the crust, the
    /// sites, misclassified points, cells, the loss curve and the stage timings.
    View(cmd_view::Args),
}

fn main() {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            // Help and version go to stdout with exit 0; usage errors exit 2.
            let _ = e.print();
            std::process::exit(if e.use_stderr() { 2 } else { 0 });
        }
    };
    let command = match (cli.command, cli.fit) {
        (Some(c), _) => c,
        (None, Some(fit)) => Command::Fit(Box::new(fit)),
        (None, None) => {
            eprintln!("error: give a mesh to fit (voronoi-fit MESH) or a subcommand; see voronoi-fit --help");
            std::process::exit(2);
        }
    };
    let result: Result<(), CliError> = match command {
        Command::Fit(args) => cmd_fit::run(*args),
        Command::Study(args) => cmd_study::run(args),
        Command::Batch(args) => cmd_batch::run(args),
        Command::Mnist(args) => cmd_mnist::run(args),
        Command::Info(args) => cmd_info::run(args),
        Command::Convert(args) => cmd_convert::run(args),
        Command::Sample(args) => cmd_sample::run(args),
        Command::Query(args) => cmd_query::run(args),
        Command::Delaunay(args) => cmd_delaunay::run(args),
        Command::Crust(args) => cmd_crust::run(args),
        Command::Eval(args) => cmd_eval::run(args),
        Command::View(args) => cmd_view::run(args),
    };
    if let Err(e) = result {
        match &e {
            CliError::Interrupted(m) => eprintln!("{m}"),
            _ => eprintln!("error: {e}"),
        }
        std::process::exit(e.exit_code());
    }
}
