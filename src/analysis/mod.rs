//! The analysis layer: what crr computes from a model, in memory. A simulation ([`simulation`],
//! behind [`crate::run`]), the `crr check` report and its static multiplier, energy levels, size
//! sweeps, Poincaré sections and studies. Nothing here writes a results folder or draws a plot;
//! those are the output layer's.

pub mod assemble;
pub mod body_sizes;
pub mod check;
pub mod contact_geometry;
pub mod inspect;
pub mod levels;
pub mod poincare;
pub mod rigid_domains;
pub mod simulation;
pub mod size_sweep;
pub mod static_multiplier;
pub mod study;
pub mod summary;

/// The most worker threads `--jobs` starts (studies, Poincaré sweeps): past the cores, threads
/// only wait, and a hundred thousand of them stalled a study that runs in 0.5 s.
pub const MAX_JOBS: usize = 1024;

/// Refuses `--jobs N` above [`MAX_JOBS`] (0 is refused where it is read).
pub fn check_max_jobs(jobs: Option<usize>) -> Result<(), crate::Error> {
    match jobs {
        Some(n) if n > MAX_JOBS => Err(crate::Error::Argument(format!(
            "--jobs must be at most {MAX_JOBS}, got {n} (this machine has {} core(s): more \
             threads than cores only wait)",
            std::thread::available_parallelism().map_or(1, |n| n.get())
        ))),
        _ => Ok(()),
    }
}
