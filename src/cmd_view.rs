//! `voronoi-fit view OUT.glb [--input MESH] [--report OUT.report.json] [--sites
//! OUT.sites.npz] [--cells CELLS.glb] [-o OUT.html]`: the arguments and the printing
//! around [`viewer::write_page`], which builds the self-contained page (the input and the
//! crust, the sites, misclassified points, cells, the loss curve and the stage timings).

use std::path::PathBuf;

use crate::cli_error::CliError;

#[derive(clap::Args, Clone, Debug)]
pub struct Args {
    /// The crust (OUT.glb from the main job, or any mesh file).
    pub crust: PathBuf,
    /// The input mesh. Default: the path OUT.report.json names.
    #[arg(long)]
    pub input: Option<PathBuf>,
    /// The fit's report. Default: OUT.report.json beside the crust.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// The sites file. Default: OUT.sites.npz beside the crust.
    #[arg(long)]
    pub sites: Option<PathBuf>,
    /// The convex cells (`voronoi-fit crust SITES --cells CELLS.glb`). Default:
    /// OUT.cells.glb beside the crust, if it exists.
    #[arg(long)]
    pub cells: Option<PathBuf>,
    /// The page. Default: OUT.html beside the crust.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Fresh samples (half uniform in the sites' cube, half within 1% of the diagonal of
    /// the surface) classified by the sites against the input to find misclassified
    /// points; 0 for none.
    #[arg(long, default_value_t = viewer::DEFAULT_CHECK_SAMPLES)]
    pub check_samples: usize,
}

impl Args {
    /// The library's options for these arguments.
    fn page_options(&self) -> viewer::PageOptions {
        viewer::PageOptions {
            crust: self.crust.clone(),
            input: self.input.clone(),
            report: self.report.clone(),
            sites: self.sites.clone(),
            cells: self.cells.clone(),
            output: self.output.clone(),
            check_samples: self.check_samples,
        }
    }
}

/// A viewer error as the binary's: the input's fault exits 2, anything else 1.
fn cli_error(e: viewer::Error) -> CliError {
    if e.is_input_fault() {
        CliError::BadInput(e.into())
    } else {
        CliError::Failure(e.into())
    }
}

pub fn run(args: Args) -> Result<(), CliError> {
    let page = viewer::write_page(&args.page_options()).map_err(cli_error)?;
    for n in &page.notes {
        eprintln!("note: {n}; the page leaves that part out");
    }
    crate::output::out!("Wrote {} ({:.1} MB).", page.path.display(), page.bytes as f64 / 1e6);
    Ok(())
}
