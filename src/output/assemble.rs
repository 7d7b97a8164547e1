//! The outputs of `crr assemble`: the contacts report and the model file written.

use std::fmt::Write;
use std::path::{Path, PathBuf};

use crr_dynamics::ground_motion::SignalSpec;

use crr_kinematics::assembly::{ContactFace, ContactSet};

use crate::Error;
use crate::analysis::assemble::Assembled;
use crate::analysis::rigid_domains::MechanismModel;
use crate::input::model_file::ModelFile;

/// One line per contact: the bodies (lower first; `ground`, or `ground (fixed NAME)` on a fixed
/// block), bed or side, area (m²), normal and number of corners.
pub fn contacts_text(a: &Assembled) -> String {
    let bodies = &a.file.body;
    let name = |c: &ContactFace, b: Option<usize>| match (b, c.support) {
        (Some(b), _) => bodies[b].name.clone(),
        (None, Some(fixed)) => format!("ground (fixed {})", a.assembly_blocks[fixed]),
        (None, None) => "ground".to_string(),
    };
    let mut s = String::new();
    let beds = a.contacts.iter().filter(|c| c.bed).count();
    let sides = match a.set {
        ContactSet::Beds => "reported only",
        ContactSet::All => "rocking interfaces",
    };
    let _ = writeln!(
        s,
        "{} contact(s): {beds} bed(s) (rocking interfaces), {} side contact(s) ({sides})",
        a.contacts.len(),
        a.contacts.len() - beds
    );
    for c in &a.contacts {
        let _ = writeln!(
            s,
            "  {}",
            contact_line(c, &name(c, c.lower), &name(c, Some(c.upper)))
        );
    }
    s
}

fn contact_line(c: &ContactFace, lower: &str, upper: &str) -> String {
    format!(
        "{lower} | {upper}: {}, area {:.6} m², normal [{:.6}, {:.6}, {:.6}], {} corners",
        if c.bed { "bed" } else { "side" },
        c.area,
        c.normal.x,
        c.normal.y,
        c.normal.z,
        c.corners.len()
    )
}

/// The model file `file` of an assembly `a` as TOML (loads back into the same model).
pub fn model_toml(a: &Assembled, file: &ModelFile) -> String {
    let header = format!(
        "# Written by `crr assemble` (crr {}): the assembly's bodies with every {} as a\n\
         # rocking interface ({} interfaces, DOF(1) = {}, {} loop closure(s)).\n",
        env!("CARGO_PKG_VERSION"),
        match a.set {
            ContactSet::Beds => "bed contact",
            ContactSet::All => "contact",
        },
        a.file.interface.len(),
        a.model.dof(),
        a.model.closures.len()
    );
    header + &ground_line(a) + &toml::to_string(file).expect("a model file serialises to TOML")
}

/// The header lines that record a ground other than the plane z = 0 (`--ground-level`; the
/// model's ground hinges lie on it, and assembling the file again needs the same option) and
/// the fixed blocks that are part of it.
fn ground_line(a: &Assembled) -> String {
    let mut lines = String::new();
    if a.ground_level != 0.0 {
        lines += &format!(
            "# The ground is the plane z = {} m (`crr assemble --ground-level {}`).\n",
            a.ground_level, a.ground_level
        );
    }
    if !a.fixed.is_empty() {
        lines += &format!(
            "# Fixed blocks, part of the ground and not in the model: {}.\n",
            a.fixed.join(", ")
        );
    }
    lines
}

/// The merged model of `crr assemble --mechanism` as TOML, with a header naming the directions.
pub fn merged_model_toml(m: &MechanismModel, file: &ModelFile) -> String {
    let a = &m.merged;
    let header = format!(
        "# Written by `crr assemble --mechanism` (crr {}): the rigid domains of the assembly's\n\
         # collapse mechanisms along {} as bodies ({} bodies from {} blocks), every contact\n\
         # between them a rocking interface ({} interfaces, DOF(1) = {}, {} loop closure(s),\n\
         # DOF(2) = {}).\n",
        env!("CARGO_PKG_VERSION"),
        m.collapses
            .iter()
            .map(|c| direction_label(c.direction))
            .collect::<Vec<_>>()
            .join(", "),
        m.domains.len(),
        m.all_contacts.file.body.len(),
        a.file.interface.len(),
        a.model.dof(),
        a.model.closures.len(),
        m.mobility.dof2
    );
    header + &ground_line(a) + &toml::to_string(file).expect("a model file serialises to TOML")
}

/// The report of `crr assemble --mechanism`: per direction λ and the interfaces that move, the
/// rigid domains with their blocks, and the merged model's DOF.
pub fn mechanism_text(m: &MechanismModel) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "limit analysis of every contact ({} blocks, {} contacts):",
        m.all_contacts.file.body.len(),
        m.all_contacts.contacts.len()
    );
    for c in &m.collapses {
        let label = direction_label(c.direction);
        let along_axis = crate::analysis::static_multiplier::out_of_plane(
            &m.all_contacts.model,
            &nalgebra::Vector3::from(c.direction),
        ) == Some(1.0);
        match c.lambda {
            None if along_axis => {
                let _ = writeln!(
                    s,
                    "  {label}: not answered: along the hinges' common axis, which the hinges of \
                     a planar model carry bilaterally"
                );
            }
            None => {
                let _ = writeln!(
                    s,
                    "  {label}: holds up to λ = {} (no mechanism)",
                    crr_impact::statics::LAMBDA_MAX
                );
            }
            Some(l) => {
                let _ = writeln!(
                    s,
                    "  {label}: λ = {l:.6}, {} moving interface(s){}: {}",
                    c.hinges.len(),
                    if c.lifts_off {
                        " (a block lifts off a support: outside the CRR chain)"
                    } else {
                        ""
                    },
                    c.hinges.join(", ")
                );
                if c.from_sliding_search {
                    let without =
                        crate::analysis::static_multiplier::without_sliding(c.convex_lambda);
                    let _ = writeln!(
                        s,
                        "    found by the search for joints that open and slide (without them \
                         {without}; the interfaces that move in either mechanism are hinges)"
                    );
                }
            }
        }
    }
    let _ = writeln!(s, "{} rigid domain(s):", m.domains.len());
    for d in &m.domains {
        if d.blocks.len() == 1 {
            let _ = writeln!(s, "  {}", d.name);
        } else {
            let _ = writeln!(
                s,
                "  {} ({} blocks): {}",
                d.name,
                d.blocks.len(),
                d.blocks.join(", ")
            );
        }
    }
    let mob = &m.mobility;
    let _ = writeln!(
        s,
        "merged model: {} bodies, {} interfaces, DOF(1) = {}, {} loop closure(s) ({} rows, rank \
         {}), DOF(2) = {}",
        m.merged.model.bodies.len(),
        m.merged.model.interfaces.len(),
        mob.dof1,
        mob.closures,
        mob.constraint_rows,
        mob.rank,
        mob.dof2
    );
    if mob.symmetries > 0 {
        let _ = writeln!(
            s,
            "with its {} symmetry row(s): DOF(3) = {}",
            mob.symmetries, mob.dof3
        );
    }
    s
}

/// `+x`, `-y`… for the axes, else the three components.
fn direction_label(d: [f64; 3]) -> String {
    let axes = ["x", "y", "z"];
    for (k, axis) in axes.iter().enumerate() {
        for sign in [1.0, -1.0] {
            let mut e = [0.0; 3];
            e[k] = sign;
            if d == e {
                return format!("{}{axis}", if sign > 0.0 { "+" } else { "-" });
            }
        }
    }
    format!("({:.6}, {:.6}, {:.6})", d[0], d[1], d[2])
}

/// Writes the model file to `out` (refused when it exists, unless `force`). A record file given
/// by a relative path (relative to the assembly's folder) is given relative to the model's folder,
/// so that the model finds it wherever it is written.
pub fn write_model(a: &Assembled, out: &Path, force: bool) -> Result<(), Error> {
    write_file(a, out, force, |file| model_toml(a, file))
}

/// Writes the merged model of `crr assemble --mechanism` to `out`, as [`write_model`].
pub fn write_merged_model(m: &MechanismModel, out: &Path, force: bool) -> Result<(), Error> {
    write_file(&m.merged, out, force, |file| merged_model_toml(m, file))
}

fn write_file(
    a: &Assembled,
    out: &Path,
    force: bool,
    text: impl Fn(&ModelFile) -> String,
) -> Result<(), Error> {
    if out.exists() && !force {
        return Err(Error::Argument(format!(
            "{}: the file exists: pass --force to replace it",
            out.display()
        )));
    }
    let mut file = a.file.clone();
    let target = out.parent().unwrap_or(Path::new(""));
    if let Some(gm) = file.ground_motion.as_mut() {
        for component in [&mut gm.x, &mut gm.y, &mut gm.z].into_iter().flatten() {
            if let SignalSpec::Record(record) = &mut component.signal
                && record.file.is_relative()
            {
                record.file = rebase(&a.folder.join(&record.file), target);
            }
        }
    }
    crate::output::replace_file::replace_file(out, text(&file)).map_err(|source| Error::Output {
        dir: out.to_path_buf(),
        source,
    })
}

/// `file` as seen from the folder `to`: relative when both resolve (the common prefix of their
/// canonical paths dropped, a `..` per remaining folder of `to`), else `file` made absolute.
fn rebase(file: &Path, to: &Path) -> PathBuf {
    let dir = if to.as_os_str().is_empty() {
        Path::new(".")
    } else {
        to
    };
    let (Ok(file_abs), Ok(dir_abs)) = (file.canonicalize(), dir.canonicalize()) else {
        // A record not there yet: an absolute path finds it wherever the model is written.
        return std::path::absolute(file).unwrap_or_else(|_| file.to_path_buf());
    };
    let (f, d): (Vec<_>, Vec<_>) = (
        file_abs.components().collect(),
        dir_abs.components().collect(),
    );
    let common = f.iter().zip(&d).take_while(|(x, y)| x == y).count();
    let mut rel = PathBuf::new();
    for _ in common..d.len() {
        rel.push("..");
    }
    for c in &f[common..] {
        rel.push(c);
    }
    rel
}
