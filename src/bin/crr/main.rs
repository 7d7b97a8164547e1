//! The `crr` command line: `main` parses the arguments and hands them to the command's file,
//! one per command; every command goes through the library (`crr::run`, the analysis and output
//! layers).

mod animate;
mod assemble;
mod check;
mod failure;
mod inspect;
mod interrupt;
mod plot;
mod poincare;
mod simulate;
mod study;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// crr: dynamics of rigid-block masonry structures by coupled rocking rotations.
#[derive(Parser)]
#[command(name = "crr", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print the coordinates, mass properties, M(q), gravity forces, U and Φ at a configuration.
    Inspect(inspect::Args),
    /// Run the simulation and write history.csv, impacts.csv and summary.json
    /// (docs/outputs.md).
    Simulate(simulate::Args),
    /// Animate a results folder written by `crr simulate`: a ParaView series (frame_NNNNN.vtu
    /// and animation.pvd) and an animated GIF (docs/animation.md).
    Animate(animate::Args),
    /// Draw the plots of a results folder written by `crr simulate`: coordinates, energy and
    /// phase (.png and .svg, docs/outputs.md); of a study folder (cases.csv and study.json): the
    /// overturning map, rocking spectrum and fragility curves (docs/studies.md).
    Plot(plot::Args),
    /// Mobility report; for a one-DOF mechanism λ, the equivalent block, r and the free-rocking
    /// frequencies (docs/outputs.md).
    Check(check::Args),
    /// Run every case of a study file (a pulse family's amplitude × frequency grid, or records
    /// scaled to intensity levels) in parallel into cases.csv and study.json (docs/studies.md);
    /// rerunning into the same folder resumes. `crr study merge DIR... --out DIR` joins shards.
    #[command(args_conflicts_with_subcommands = true)]
    Study(study::Args),
    /// Poincaré section under the harmonic ground acceleration A sin(2πF t + φ): the states at
    /// t = kT (T = 1/F), or where a coordinate crosses 0 upward (--section, or --amplitude 0);
    /// sweeps give a bifurcation diagram or basins (docs/poincare.md).
    Poincare(poincare::Args),
    /// From geometry to hinges: the contact faces of an assembly of blocks (bodies only) and the
    /// model whose rocking interfaces they are (docs/assembly.md).
    Assemble(assemble::Args),
}

fn main() -> ExitCode {
    quiet_on_broken_pipe();
    let result = match Cli::parse().command {
        Command::Inspect(a) => inspect::run(a),
        Command::Simulate(a) => simulate::run(a),
        Command::Animate(a) => animate::run(a),
        Command::Plot(a) => plot::run(a),
        Command::Check(a) => check::run(a),
        Command::Study(a) => study::run(a),
        Command::Poincare(a) => poincare::run(a),
        Command::Assemble(a) => assemble::run(a),
    };
    failure::exit_code(result)
}

/// A standard output closed by its reader (`crr check --json | head`) ends the program quietly
/// with 141 (128 + SIGPIPE, what a shell reports for a tool that the signal ends), as other
/// command-line tools do, instead of with `print!`'s panic and a backtrace. Files are written
/// before their summaries are printed, so nothing computed is lost.
fn quiet_on_broken_pipe() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let message = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or("");
        if message.starts_with("failed printing to stdout") && message.contains("Broken pipe") {
            std::process::exit(141);
        }
        default(info);
    }));
}
