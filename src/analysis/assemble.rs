//! `crr assemble`: blocks in contact in, a CRR model out (docs/assembly.md). The assembly file is
//! a model file with bodies only; the contact faces are found from the bodies' shapes
//! ([`crr_kinematics::assembly`]) and every bed contact (or, on request, every contact) becomes a
//! rocking interface, the spanning tree and the loops chosen as for any model file.

use std::path::Path;

use crr_kinematics::assembly::{
    ContactFace, ContactSet, InterfaceStyle, detect_contacts, free_blocks, inscribed_rectangle,
    is_rectangle, near_misses, structure_of,
};
use crr_kinematics::{Model, StructureSpec};

use crate::Error;
use crate::input::model_file::{ModelFile, read_model_file};
use crate::input::obj::obj_bodies;

/// The default contact tolerance (m): two faces closer than this touch.
pub const DEFAULT_TOLERANCE: f64 = 1e-6;

/// How an assembly becomes a model: which contacts are interfaces, of which kind, and the
/// geometry's tolerance and ground.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AssemblyOptions {
    /// A planar layout in the x–z plane: hinges about y instead of rocking bases.
    pub planar: bool,
    /// Which contacts become interfaces: the beds, or every contact.
    pub contacts: ContactSet,
    /// Faces closer than this touch (m).
    pub tolerance: f64,
    /// The height of the ground (m): a site elevation where the blocks' coordinates are a
    /// survey's (the ground is the plane z = 0 by default).
    pub ground_level: f64,
    /// A contact face that is no rectangle (a drum's polygon) becomes the largest rectangle of
    /// its bounding box's proportions inside it ([`inscribed_rectangle`]): a rocking base is a
    /// rectangle, and the multipliers are then lower bounds of the whole face's. Refused when
    /// false.
    pub inscribed: bool,
}

impl AssemblyOptions {
    /// These options with a planar layout (`crr assemble --planar`): hinges about y.
    pub fn in_plane(self) -> Self {
        Self {
            planar: true,
            ..self
        }
    }

    /// These options with every contact an interface (`crr assemble --all-contacts`).
    pub fn with_all_contacts(self) -> Self {
        Self {
            contacts: ContactSet::All,
            ..self
        }
    }
}

impl Default for AssemblyOptions {
    /// Rocking bases on the bed contacts, the default tolerance, the ground at z = 0.
    fn default() -> Self {
        Self {
            planar: false,
            contacts: ContactSet::Beds,
            tolerance: DEFAULT_TOLERANCE,
            ground_level: 0.0,
            inscribed: false,
        }
    }
}

/// Reads an assembly file: a model file (TOML, or JSON when it ends in .json) with bodies (its
/// `[[body]]` tables, then the blocks of its `[[obj]]` files) and no interfaces.
pub fn read_assembly(path: &Path) -> Result<ModelFile, Error> {
    let mut file = read_model_file(path)?;
    // The blocks of `[[obj]]` files become bodies after the `[[body]]` ones.
    let folder = path.parent().unwrap_or(Path::new(""));
    for spec in std::mem::take(&mut file.obj) {
        file.body.extend(obj_bodies(&spec, folder)?);
    }
    let names: Vec<&str> = file.body.iter().map(|b| b.name.as_str()).collect();
    if let Some((i, name)) = names
        .iter()
        .enumerate()
        .find(|(i, n)| names[..*i].contains(n))
    {
        return Err(Error::Argument(format!(
            "{}: body \"{name}\" is named twice (body {} of the assembly, with its [[obj]] \
             blocks after its [[body]] tables)",
            path.display(),
            i + 1
        )));
    }
    let here = |m: &str| Error::Argument(format!("{}: {m}", path.display()));
    if !file.interface.is_empty() {
        return Err(here(
            "an assembly lists bodies only: `crr assemble` finds the interfaces (remove the \
             [[interface]] tables, or simulate the file as a model)",
        ));
    }
    if file.body.is_empty() {
        return Err(here("the assembly has no [[body]]"));
    }
    if let Some(name) = file.fixed.iter().find(|f| !names.contains(&f.as_str())) {
        return Err(here(&format!(
            "fixed: no block is named \"{name}\" (the blocks are the [[body]] tables and the \
             objects of the [[obj]] files)"
        )));
    }
    if let Some((i, name)) = file
        .fixed
        .iter()
        .enumerate()
        .find(|(i, f)| file.fixed[..*i].contains(f))
    {
        return Err(here(&format!(
            "fixed: \"{name}\" is named twice (entries {} and {})",
            file.fixed[..i].iter().position(|f| f == name).unwrap_or(0) + 1,
            i + 1
        )));
    }
    if names.iter().all(|n| file.fixed.iter().any(|f| f == n)) {
        return Err(here(
            "fixed: every block is fixed, so nothing can move (fixed names the blocks that are \
             part of the ground)",
        ));
    }
    Ok(file)
}

/// An assembly turned into a model.
#[derive(Clone, Debug)]
pub struct Assembled {
    /// Every contact face found (beds and side contacts).
    pub contacts: Vec<ContactFace>,
    /// Which of them are the model's interfaces.
    pub set: ContactSet,
    /// The model file written: the assembly's tables with the interfaces added.
    pub file: ModelFile,
    /// The model it builds.
    pub model: Model,
    /// The folder of the assembly file (its relative record paths start there).
    pub folder: std::path::PathBuf,
    /// The height of the ground plane its contacts were found on (m; `--ground-level`).
    pub ground_level: f64,
    /// The blocks that were part of the ground (the assembly's `fixed`), not in the model.
    pub fixed: Vec<String>,
    /// The names of the assembly's blocks, fixed ones included (`ContactFace::support` indexes
    /// them).
    pub assembly_blocks: Vec<String>,
    /// What to know about the model written: blocks whose faces face each other a little
    /// farther apart than the tolerance (`near_misses`), which are no contact.
    pub warnings: Vec<String>,
}

/// Finds the contacts of the assembly `file` (read from `path`) on the ground of `options` and
/// builds the model whose interfaces are its contacts (every bed, or every contact): rocking
/// bases, or hinges about y when planar.
pub fn assemble(
    path: &Path,
    file: &ModelFile,
    options: &AssemblyOptions,
) -> Result<Assembled, Error> {
    let &AssemblyOptions {
        planar,
        contacts: set,
        tolerance,
        ground_level,
        inscribed,
    } = options;
    let here = |e: &dyn std::fmt::Display| Error::Argument(format!("{}: {e}", path.display()));
    let fixed: Vec<bool> = file
        .body
        .iter()
        .map(|b| file.fixed.contains(&b.name))
        .collect();
    let found =
        detect_contacts(&file.body, tolerance, set, ground_level, &fixed).map_err(|e| here(&e))?;
    // The fixed blocks are ground: the model is the free blocks.
    let (free, mut contacts) = free_blocks(&file.body, &found, &fixed);
    let interface = |c: &ContactFace| c.bed || set == ContactSet::All;
    if inscribed && !planar {
        for c in contacts.iter_mut().filter(|c| interface(c)) {
            if !is_rectangle(&c.corners, tolerance) {
                *c = inscribed_rectangle(c);
            }
        }
    }
    let style = if planar {
        InterfaceStyle::PlanarHinge
    } else {
        InterfaceStyle::RockingBase
    };
    let spec: StructureSpec = structure_of(
        &file.name,
        file.gravity,
        &free,
        &contacts,
        style,
        set,
        tolerance,
    )
    .map_err(|e| here(&e))?;
    // A rocking base is a rectangle (named as the model names it).
    if let Some((name, corners)) = spec.interface.iter().find_map(|i| {
        let corners: Vec<nalgebra::Vector3<f64>> = i
            .rocking_base
            .as_ref()?
            .corners
            .iter()
            .map(|c| nalgebra::Vector3::from(*c))
            .collect();
        (!is_rectangle(&corners, tolerance)).then_some((i.name.as_str(), corners.len()))
    }) {
        return Err(here(&format!(
            "contact \"{name}\": its face is a polygon of {corners} corners, not a rectangle, \
             and a rocking base is a rectangle: `crr assemble --inscribed` takes the largest \
             rectangle of the face's proportions inside it (its multipliers are lower bounds of \
             the whole face's)"
        )));
    }
    // The assembly's [[symmetry]] tables name coordinates of the model written: checked here.
    let spec = StructureSpec {
        symmetry: file.symmetry.clone(),
        ..spec
    };
    let out = ModelFile {
        body: spec.body.clone(),
        interface: spec.interface.clone(),
        fixed: Vec::new(),
        ..file.clone()
    };
    let model = Model::from_spec(&spec).map_err(|source| Error::Model {
        file: path.to_path_buf(),
        source,
    })?;
    Ok(Assembled {
        contacts,
        set,
        file: out,
        model,
        folder: path.parent().map(Path::to_path_buf).unwrap_or_default(),
        ground_level,
        fixed: file.fixed.clone(),
        assembly_blocks: file.body.iter().map(|b| b.name.clone()).collect(),
        warnings: near_miss_warnings(file, &found, &fixed, tolerance, set),
    })
}

/// A warning for each pair of blocks with no contact between them whose faces face each other
/// a little farther apart than the tolerance ([`near_misses`]): a trilithon whose right post
/// was drawn 0.5 mm short was written with its lintel on the left post alone, without a word
/// (its multiplier then that of a lintel on one post).
fn near_miss_warnings(
    file: &ModelFile,
    found: &[ContactFace],
    fixed: &[bool],
    tolerance: f64,
    set: ContactSet,
) -> Vec<String> {
    let touching = |i: usize, j: usize| {
        let ends = |c: &ContactFace| {
            let lower = c.lower.or(c.support);
            [(Some(c.upper), lower), (lower, Some(c.upper))]
        };
        found.iter().any(|c| ends(c).contains(&(Some(i), Some(j))))
    };
    near_misses(&file.body, tolerance, fixed)
        .into_iter()
        // Without --all-contacts only beds are interfaces: a side face (a head joint drawn
        // open) joined by a larger tolerance would be reported, not used.
        .filter(|m| (m.bed || set == ContactSet::All) && !touching(m.bodies.0, m.bodies.1))
        .map(|m| {
            format!(
                "blocks \"{}\" and \"{}\" have faces facing each other {:.3e} m apart, more \
                 than the tolerance ({tolerance} m): they are no contact, and the model has no \
                 interface between them; if the gap is the drawing's and not the structure's, \
                 `--tolerance {:.2e}` makes it one",
                file.body[m.bodies.0].name,
                file.body[m.bodies.1].name,
                m.gap,
                m.gap * 1.1
            )
        })
        .collect()
}
