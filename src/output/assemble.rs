//! The outputs of `crr assemble`: the contacts report and the model file written.

use std::fmt::Write;
use std::path::Path;

use crr_kinematics::assembly::ContactFace;

use crate::Error;
use crate::analysis::assemble::Assembled;

/// One line per contact: the bodies (lower first; `ground`), bed or side, area (m²), normal and
/// number of corners.
pub fn contacts_text(a: &Assembled) -> String {
    let bodies = &a.file.body;
    let name = |b: Option<usize>| b.map_or("ground", |b| bodies[b].name.as_str());
    let mut s = String::new();
    let beds = a.contacts.iter().filter(|c| c.bed).count();
    let _ = writeln!(
        s,
        "{} contact(s): {beds} bed(s) (rocking interfaces), {} side contact(s) (reported only)",
        a.contacts.len(),
        a.contacts.len() - beds
    );
    for c in &a.contacts {
        let _ = writeln!(
            s,
            "  {}",
            contact_line(c, name(c.lower), name(Some(c.upper)))
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

/// The model file of an assembly as TOML (loads back into the same model).
pub fn model_toml(a: &Assembled) -> String {
    let header = format!(
        "# Written by `crr assemble` (crr {}): the assembly's bodies with every bed contact as a\n\
         # rocking interface ({} interfaces, DOF(1) = {}, {} loop closure(s)).\n",
        env!("CARGO_PKG_VERSION"),
        a.file.interface.len(),
        a.model.dof(),
        a.model.closures.len()
    );
    header + &toml::to_string(&a.file).expect("a model file serialises to TOML")
}

/// Writes the model file to `out` (refused when it exists, unless `force`).
pub fn write_model(a: &Assembled, out: &Path, force: bool) -> Result<(), Error> {
    if out.exists() && !force {
        return Err(Error::Argument(format!(
            "{}: the file exists: pass --force to replace it",
            out.display()
        )));
    }
    crate::output::replace_file::replace_file(out, model_toml(a)).map_err(|source| Error::Output {
        dir: out.to_path_buf(),
        source,
    })
}
