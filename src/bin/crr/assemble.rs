//! `crr assemble ASSEMBLY [--contacts] [--out MODEL.toml] [--all-contacts] [--planar]
//! [--tolerance T] [--force]`.

use std::path::PathBuf;

use crr::analysis::assemble::{DEFAULT_TOLERANCE, assemble, read_assembly};
use crr::kinematics::assembly::ContactSet;
use crr::output::assemble::{contacts_text, write_model};

use crate::failure::Failure;

/// The arguments of `crr assemble`.
#[derive(clap::Args)]
pub(crate) struct Args {
    /// Assembly file: bodies only, as in a model file (docs/assembly.md).
    pub(crate) assembly: PathBuf,
    /// List every contact found (bodies, bed or side, area, normal).
    #[arg(long)]
    pub(crate) contacts: bool,
    /// Write the model (every bed contact, or every contact, a rocking interface) to this file.
    #[arg(long, value_name = "MODEL.toml")]
    pub(crate) out: Option<PathBuf>,
    /// Every contact face becomes an interface (the inclined joints of an arch, head joints),
    /// not only the beds; each interface's parent is the body nearer the ground.
    #[arg(long)]
    pub(crate) all_contacts: bool,
    /// A planar layout in the x–z plane: hinges about y instead of rocking bases.
    #[arg(long)]
    pub(crate) planar: bool,
    /// Faces closer than this touch (m).
    #[arg(long, default_value_t = DEFAULT_TOLERANCE)]
    pub(crate) tolerance: f64,
    /// Replace an existing model file.
    #[arg(long)]
    pub(crate) force: bool,
}

pub(crate) fn run(a: Args) -> Result<(), Failure> {
    let file = read_assembly(&a.assembly)?;
    let set = if a.all_contacts {
        ContactSet::All
    } else {
        ContactSet::Beds
    };
    let assembled = assemble(&a.assembly, &file, a.planar, set, a.tolerance)?;
    if a.contacts || a.out.is_none() {
        print!("{}", contacts_text(&assembled));
    }
    if let Some(out) = &a.out {
        write_model(&assembled, out, a.force)?;
        println!(
            "model written to {} ({} interfaces, DOF(1) = {}, {} loop closure(s))",
            out.display(),
            assembled.file.interface.len(),
            assembled.model.dof(),
            assembled.model.closures.len()
        );
    }
    Ok(())
}
