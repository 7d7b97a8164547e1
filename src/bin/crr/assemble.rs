//! `crr assemble ASSEMBLY [--contacts] [--out MODEL.toml] [--all-contacts] [--planar]
//! [--mechanism [--direction D]…] [--tolerance T] [--ground-level Z] [--inscribed] [--force]`.

use std::path::PathBuf;

use crr::Error;
use crr::analysis::assemble::{AssemblyOptions, DEFAULT_TOLERANCE, assemble, read_assembly};
use crr::analysis::rigid_domains::mechanism_model;
use crr::analysis::static_multiplier::parse_direction;
use crr::input::model_file::ModelFile;
use crr::kinematics::assembly::ContactSet;
use crr::output::assemble::{contacts_text, mechanism_text, write_merged_model, write_model};
use nalgebra::Vector3;

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
    /// The height of the ground (m), for blocks given in a survey's coordinates: faces on the
    /// plane z = Z rest on the ground.
    #[arg(
        long,
        value_name = "Z",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    pub(crate) ground_level: f64,
    /// A contact face that is no rectangle (a drum's polygon) becomes the largest rectangle of
    /// the proportions of its bounding box inside it (centred at its centroid): a rocking base
    /// is a rectangle, and the multipliers are then lower bounds of the whole face's.
    #[arg(long)]
    pub(crate) inscribed: bool,
    /// The limit analysis of the assembly (every contact an interface) along each direction, and
    /// the model of its rigid domains: the interfaces that move in any mechanism are hinges, the
    /// blocks no mechanism separates one compound body.
    #[arg(long)]
    pub(crate) mechanism: bool,
    /// A direction of the ground acceleration for --mechanism (±x, ±y, ±z or X,Y,Z; repeat it),
    /// instead of ±x (and ±y without --planar).
    #[arg(
        long,
        value_name = "D",
        allow_hyphen_values = true,
        requires = "mechanism"
    )]
    pub(crate) direction: Vec<String>,
    /// Replace an existing model file.
    #[arg(long)]
    pub(crate) force: bool,
}

pub(crate) fn run(a: Args) -> Result<(), Failure> {
    let file = read_assembly(&a.assembly)?;
    if a.mechanism {
        return run_mechanism(&a, &file);
    }
    let assembled = assemble(&a.assembly, &file, &options(&a))?;
    for w in &assembled.warnings {
        eprintln!("crr: warning: {}: {w}", a.assembly.display());
    }
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

/// The options of the arguments `a`.
fn options(a: &Args) -> AssemblyOptions {
    AssemblyOptions {
        planar: a.planar,
        contacts: if a.all_contacts {
            ContactSet::All
        } else {
            ContactSet::Beds
        },
        tolerance: a.tolerance,
        ground_level: a.ground_level,
        inscribed: a.inscribed,
    }
}

/// `crr assemble --mechanism`: the report, and the merged model written with `--out`.
fn run_mechanism(a: &Args, file: &ModelFile) -> Result<(), Failure> {
    let directions = if a.direction.is_empty() {
        let mut d = vec![Vector3::x(), -Vector3::x()];
        if !a.planar {
            d.extend([Vector3::y(), -Vector3::y()]);
        }
        d
    } else {
        a.direction
            .iter()
            .map(|d| parse_direction(d))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| Failure::Input(Error::Argument(format!("--direction: {e}"))))?
    };
    let m = mechanism_model(&a.assembly, file, &directions, &options(a))?;
    for w in &m.all_contacts.warnings {
        eprintln!("crr: warning: {}: {w}", a.assembly.display());
    }
    if a.contacts {
        print!("{}", contacts_text(&m.all_contacts));
    }
    print!("{}", mechanism_text(&m));
    if let Some(out) = &a.out {
        write_merged_model(&m, out, a.force)?;
        println!("model written to {}", out.display());
    }
    Ok(())
}
