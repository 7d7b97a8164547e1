//! `crr assemble --mechanism`: the limit analysis of an assembly along each direction asked for,
//! and the smallest CRR model that contains every one of its collapse mechanisms (the paper's
//! path from the geometry to the hinges: the plastic hinges from a limit analysis, the continuum
//! partitioned into rigid domains, DOF(1), then the hinge constraints, DOF(2)).
//!
//! Stages:
//! 1. the model of every contact ([`assemble`] with [`ContactSet::All`]);
//! 2. its collapse multiplier and mechanism along each direction, by the static theorem on the
//!    contact faces ([`crr_impact::statics::collapse_multiplier`]);
//! 3. the interfaces that move in any mechanism are the hinges; the blocks joined by interfaces
//!    that stay closed in every mechanism form one rigid domain (union–find);
//! 4. each domain of several blocks becomes a compound body (its mass properties the exact sums
//!    of its blocks'), the contacts between domains its interfaces (coplanar faces of one pair
//!    as one face, [`merge_coplanar`]), the tree and loops chosen as for any assembly.
//!
//! Where several mechanisms are optimal along a direction, the one read is not the first one a
//! search meets: the program is solved by an interior point, whose answer lies inside the face of
//! optimal solutions, so it moves every interface that some optimal mechanism moves (a mirrored
//! direction gives the mirrored hinges: the arch's domains are symmetric).
//!
//! The merged model has the same multiplier as the model of every contact along each direction
//! asked for, by the program without sliding: merging adds rigidity only where the mechanism has
//! none (so its mechanism is still admissible, λ_merged ≤ λ_all), and a merged model's mechanism
//! is one of the full model's (λ_merged ≥ λ_all). `tests/cli/mechanism.rs` checks it on every
//! bundled assembly. Where the search for joints that open and slide finds a lower λ (a block
//! lifting off one support while sliding over another), the interfaces its mechanism moves are
//! hinges as well, so that mechanism with its equilibrium is one of the merged model's too; the
//! merged model's own search is not exhaustive and may answer another.

use std::path::Path;

use nalgebra::{DVector, Vector3};
use serde::Serialize;

use crr_dynamics::{Mobility, mobility};
use crr_impact::statics::{Motion, StaticsOptions, collapse_multiplier};
use crr_kinematics::assembly::{
    ContactFace, ContactSet, InterfaceStyle, merge_coplanar, structure_of,
};
use crr_kinematics::spec::{BlockSpec, BodySpec, SymmetrySpec};
use crr_kinematics::{ActivePivots, DisjointSets, Model, Parent, Side, StructureSpec};

use crate::Error;
use crate::analysis::assemble::{Assembled, AssemblyOptions, assemble};
use crate::input::model_file::ModelFile;

/// The collapse along one direction of the assembly of every contact.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DirectionCollapse {
    /// Unit direction d of the ground acceleration.
    pub direction: [f64; 3],
    /// λ (in g); `None` when the assembly holds up to the statics' λ_max.
    pub lambda: Option<f64>,
    /// The interfaces of the model of every contact that move in the mechanism (`UPPER_on_LOWER`),
    /// and, where `lambda` comes from the search for joints that open and slide, those that move
    /// in the mechanism of the program without sliding too.
    pub hinges: Vec<String>,
    /// Whether the mechanism lifts a block off a support (outside the CRR chain).
    pub lifts_off: bool,
    /// Whether `lambda` comes from the search for joints that open and slide
    /// ([`crr_impact::statics::Collapse::from_sliding_search`]), below `convex_lambda`.
    pub from_sliding_search: bool,
    /// The program without sliding's λ (`None`: it holds up to λ_max); the merged model keeps it.
    pub convex_lambda: Option<f64>,
}

/// One rigid domain: a body of the merged model and the blocks it is made of.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Domain {
    /// Its body's name: the block's own for a domain of one block, else `domain_FIRST` after its
    /// first block in the assembly's order.
    pub name: String,
    /// The blocks, in the assembly's order.
    pub blocks: Vec<String>,
}

/// An assembly reduced to the rigid domains of its collapse mechanisms.
#[derive(Clone, Debug)]
pub struct MechanismModel {
    /// The model of every contact (each block a body).
    pub all_contacts: Assembled,
    /// The collapse along each direction asked for.
    pub collapses: Vec<DirectionCollapse>,
    /// The rigid domains, in the order of their first blocks.
    pub domains: Vec<Domain>,
    /// The merged model: a body per domain, an interface per contact between domains.
    pub merged: Assembled,
    /// Its mobility at rest: DOF(1), the loops, DOF(2) and, with the assembly's `[[symmetry]]`
    /// tables (naming the merged model's coordinates), DOF(3).
    pub mobility: Mobility,
}

/// The limit analysis of the assembly `file` (read from `path`) along `directions` and its
/// merged model (hinges about y with `options.planar`, else rocking bases; every contact an
/// interface, whatever `options.contacts`).
pub fn mechanism_model(
    path: &Path,
    file: &ModelFile,
    directions: &[Vector3<f64>],
    options: &AssemblyOptions,
) -> Result<MechanismModel, Error> {
    let (planar, tolerance) = (options.planar, options.tolerance);
    // The assembly's [[symmetry]] tables name coordinates of the merged model, not of this one.
    let blocks_only = ModelFile {
        symmetry: Vec::new(),
        ..file.clone()
    };
    let all = assemble(path, &blocks_only, &options.with_all_contacts())?;
    // One limit analysis per direction, each on its own thread (independent programs; the
    // answers are collected in the directions' order, so the result does not depend on timing).
    let collapses = std::thread::scope(|scope| {
        let handles: Vec<_> = directions
            .iter()
            .map(|d| scope.spawn(|| collapse_along(&all.model, *d)))
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
            .collect::<Result<Vec<_>, _>>()
    })
    .map_err(|e| Error::Argument(format!("{}: {e}", path.display())))?;
    let domain_of = rigid_domains(&all.model, &collapses);
    let domains = domain_list(&all, &domain_of);
    let merged = merged_model(
        path,
        &all,
        &domain_of,
        &domains,
        planar,
        tolerance,
        &file.symmetry,
    )?;
    let zero = DVector::zeros(merged.model.dof());
    let mobility = mobility(
        &merged.model,
        &zero,
        &ActivePivots::uniform(&merged.model, Side::Positive),
    );
    Ok(MechanismModel {
        all_contacts: all,
        collapses,
        domains,
        merged,
        mobility,
    })
}

/// The collapse of `model` along `direction` and the interfaces that move in it.
/// Where the search for joints that open and slide lowers λ, the mechanism of the program
/// without sliding is read as well and its moving interfaces are hinges too: the merged model
/// then keeps that program's λ exactly (see the module's docs), and the sliding mechanism's
/// blocks stay separate.
fn collapse_along(model: &Model, direction: Vector3<f64>) -> Result<DirectionCollapse, String> {
    let c = collapse_multiplier(model, direction, &StaticsOptions::default())
        .map_err(|e| e.to_string())?;
    let moving = |c: &crr_impact::statics::Collapse| -> Vec<usize> {
        c.interfaces
            .iter()
            .filter(|i| i.motion != Motion::Closed)
            .map(|i| i.interface)
            .collect()
    };
    let mut hinges = moving(&c);
    if c.from_sliding_search() {
        let without_sliding = StaticsOptions {
            sliding_lift_off: false,
            ..StaticsOptions::default()
        };
        let convex =
            collapse_multiplier(model, direction, &without_sliding).map_err(|e| e.to_string())?;
        hinges.extend(moving(&convex));
        hinges.sort_unstable();
        hinges.dedup();
    }
    Ok(DirectionCollapse {
        direction: c.direction,
        lambda: c.lambda,
        hinges: hinges
            .into_iter()
            .map(|k| model.interfaces[k].name.clone())
            .collect(),
        lifts_off: c.lifting_off().next().is_some(),
        from_sliding_search: c.from_sliding_search(),
        convex_lambda: c.convex_lambda,
    })
}

/// The domain of each body: bodies joined by an interface that no mechanism moves are one
/// domain (union–find with the smaller index as the root, so a domain is named by its first
/// block). Domains are numbered in the order of their first bodies.
fn rigid_domains(model: &Model, collapses: &[DirectionCollapse]) -> Vec<usize> {
    let n = model.bodies.len();
    let mut sets = DisjointSets::new(n);
    for iface in &model.interfaces {
        let Parent::Body(p) = iface.parent else {
            continue;
        };
        let moves = collapses.iter().any(|c| c.hinges.contains(&iface.name));
        if !moves {
            sets.union(p, iface.child);
        }
    }
    let roots: Vec<usize> = (0..n).map(|b| sets.find(b)).collect();
    let mut number = vec![usize::MAX; n];
    let mut next = 0;
    for &r in &roots {
        if number[r] == usize::MAX {
            number[r] = next;
            next += 1;
        }
    }
    roots.iter().map(|&r| number[r]).collect()
}

/// The domains' names and blocks.
fn domain_list(all: &Assembled, domain_of: &[usize]) -> Vec<Domain> {
    let count = domain_of.iter().max().map_or(0, |m| m + 1);
    let names: Vec<&str> = all.file.body.iter().map(|b| b.name.as_str()).collect();
    (0..count)
        .map(|d| {
            let blocks: Vec<String> = domain_of
                .iter()
                .zip(&names)
                .filter(|(k, _)| **k == d)
                .map(|(_, n)| n.to_string())
                .collect();
            let name = if blocks.len() == 1 {
                blocks[0].clone()
            } else {
                // A name no block has.
                let mut name = format!("domain_{}", blocks[0]);
                while names.contains(&name.as_str()) {
                    name.push('_');
                }
                name
            };
            Domain { name, blocks }
        })
        .collect()
}

/// The model of the domains: each a body (a compound body of its blocks, each block with its own
/// density), the contacts between domains its interfaces, with the `symmetry` rows given.
fn merged_model(
    path: &Path,
    all: &Assembled,
    domain_of: &[usize],
    domains: &[Domain],
    planar: bool,
    tolerance: f64,
    symmetry: &[SymmetrySpec],
) -> Result<Assembled, Error> {
    let bodies: Vec<BodySpec> = domains
        .iter()
        .enumerate()
        .map(|(d, domain)| {
            let members: Vec<usize> = (0..domain_of.len())
                .filter(|&b| domain_of[b] == d)
                .collect();
            if let [single] = members[..] {
                return all.file.body[single].clone();
            }
            let blocks = members
                .iter()
                .flat_map(|&b| {
                    let spec = &all.file.body[b];
                    // The density the model uses for it (its mass over its volume when a mass
                    // is given).
                    let density = all.model.bodies[b].density;
                    let shape = spec
                        .own_shapes()
                        .pop()
                        .expect("an assembly block has one shape");
                    BlockSpec::all_of(Some(spec.name.clone()), Some(density), shape)
                })
                .collect();
            BodySpec {
                name: domain.name.clone(),
                density: None,
                mass: None,
                box_shape: None,
                polyhedron: None,
                prism: None,
                annular_sector: None,
                blocks,
            }
        })
        .collect();
    let between: Vec<ContactFace> = all
        .contacts
        .iter()
        .filter_map(|c| {
            let upper = domain_of[c.upper];
            let lower = c.lower.map(|l| domain_of[l]);
            (lower != Some(upper)).then(|| ContactFace {
                lower,
                upper,
                ..c.clone()
            })
        })
        .collect();
    let style = if planar {
        InterfaceStyle::PlanarHinge
    } else {
        InterfaceStyle::RockingBase
    };
    let contacts = merge_coplanar(&between, style, tolerance);
    let here = |e: &dyn std::fmt::Display| Error::Argument(format!("{}: {e}", path.display()));
    let spec = structure_of(
        &all.file.name,
        all.file.gravity,
        &bodies,
        &contacts,
        style,
        ContactSet::All,
        tolerance,
    )
    .map_err(|e| here(&e))?;
    let spec = StructureSpec {
        symmetry: symmetry.to_vec(),
        ..spec
    };
    let file = ModelFile {
        body: spec.body.clone(),
        interface: spec.interface.clone(),
        symmetry: symmetry.to_vec(),
        ..all.file.clone()
    };
    let model = Model::from_spec(&spec).map_err(|source| Error::Model {
        file: path.to_path_buf(),
        source,
    })?;
    Ok(Assembled {
        contacts,
        set: ContactSet::All,
        file,
        model,
        folder: all.folder.clone(),
        ground_level: all.ground_level,
        fixed: all.fixed.clone(),
        assembly_blocks: all.assembly_blocks.clone(),
        // The blocks' near misses are those of the assembly of every contact.
        warnings: all.warnings.clone(),
    })
}
