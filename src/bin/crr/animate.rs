//! `crr animate RESULTS_DIR`: a ParaView series and an animated GIF of a run.

use std::path::PathBuf;

use crr::Error;
use crr::output::animate::{AnimateOptions, AnimateReport, GIF_FILE, PVD_FILE, animate};

use crate::failure::Failure;

/// The arguments of `crr animate`.
#[derive(clap::Args)]
pub(crate) struct Args {
    /// The results folder (history.csv and summary.json).
    #[arg(value_name = "RESULTS_DIR")]
    pub(crate) dir: PathBuf,
    /// Keep every K-th state of history.csv (default: about 0.05 s between frames, at most
    /// 400 frames).
    #[arg(long, value_name = "K")]
    pub(crate) every: Option<usize>,
    /// Output folder (default RESULTS_DIR/animation).
    #[arg(long, value_name = "DIR")]
    pub(crate) out: Option<PathBuf>,
    /// The GIF's view: x, y, z (orthographic along that axis) or iso (isometric).
    #[arg(long, value_name = "VIEW", default_value = "iso")]
    pub(crate) view: String,
    /// Files to write: vtk (the ParaView series), gif, or both.
    #[arg(long, value_name = "FORMAT", default_value = "both")]
    pub(crate) format: String,
    /// GIF playback speed: 1 is real time, 0.5 half speed.
    #[arg(long, value_name = "S", default_value_t = 1.0)]
    pub(crate) speed: f64,
    /// Replace an earlier animation in the output folder.
    #[arg(long)]
    pub(crate) force: bool,
}

pub(crate) fn run(a: Args) -> Result<(), Failure> {
    let arg = Error::Argument;
    let opts = AnimateOptions {
        every: a.every,
        out: a.out,
        view: a.view.parse().map_err(|e| arg(format!("--view: {e}")))?,
        format: a
            .format
            .parse()
            .map_err(|e| arg(format!("--format: {e}")))?,
        speed: a.speed,
        force: a.force,
    };
    let report = animate(&a.dir, &opts)?;
    print_animation(&report);
    Ok(())
}

/// The lines `crr animate` prints: what was written.
pub(crate) fn print_animation(r: &AnimateReport) {
    println!(
        "{} frame(s) (every {} state(s) of history.csv) in {}",
        r.frames,
        r.every,
        r.out.display()
    );
    if let Some(bytes) = r.gif_bytes {
        println!(
            "{} ({:.1} kB)",
            r.out.join(GIF_FILE).display(),
            bytes as f64 / 1000.0
        );
    }
    if r.files.iter().any(|f| f.ends_with(PVD_FILE)) {
        println!("{}", r.out.join(PVD_FILE).display());
    }
}
