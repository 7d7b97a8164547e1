//! How a command fails: input problems and plots that cannot be drawn exit with 2, a simulation
//! that failed part-way (its partial results written) with 1.

use std::process::ExitCode;

use crr::{Error, PlotError};

/// A command's failure.
pub(crate) enum Failure {
    /// An input, an option or an output folder is wrong (exit 2).
    Input(Error),
    /// A simulation stopped part-way (exit 1).
    Simulation(String),
}

impl From<Error> for Failure {
    fn from(e: Error) -> Self {
        Failure::Input(e)
    }
}

impl From<PlotError> for Failure {
    fn from(e: PlotError) -> Self {
        Failure::Input(Error::Plot(e))
    }
}

/// Prints the failure after `crr: error: ` and gives the exit status.
pub(crate) fn exit_code(result: Result<(), Failure>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Input(e)) => {
            eprintln!("crr: error: {e}");
            ExitCode::from(2)
        }
        Err(Failure::Simulation(e)) => {
            eprintln!("crr: error: {e}");
            ExitCode::from(1)
        }
    }
}
