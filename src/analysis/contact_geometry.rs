//! Whether each interface of a model written by hand sits where its bodies touch: its pivots on
//! the surfaces of both bodies, and the two bodies touching without overlapping at rest. A pivot
//! typed 2.0 for 0.2, or a block placed 0.2 m above the joint it rocks on, gives a model that
//! runs and answers with confidence (λ = 2 for a block of b/h = 0.2); `crr assemble` checks its
//! own contacts, and these checks give a hand-written file the same scrutiny, as warnings of
//! `crr check` and `crr simulate` (a model may place a pivot off its bodies on purpose).
//!
//! A hinge's pivot is a line: the point the file gives, or the point of the line nearest the
//! body's centre of mass, must lie on that body's surface (a line along an edge of a block
//! touches the block at its point nearest the centre, whatever point of the line the file
//! gives; the point given serves an edge that does not span the centre). A pin (one pivot
//! line, a joint that is not a contact: [`ContactFace::is_pin`]) is not checked. A rocking
//! base's corners must each lie on both surfaces. The ground has no surface: only the child is
//! checked on it. Bodies' surfaces are those of their shapes at rest (an annular sector's arcs
//! as chords), and a point counts as on a surface within [`ON_SURFACE`] of the model size.

use crr_kinematics::interpenetration::{distance_to_surface, interpenetration};
use crr_kinematics::shapes::Surface;
use crr_kinematics::{ContactFace, InterfaceKind, Model, Parent, contact_faces};
use nalgebra::Vector3;

/// How far (a fraction of the model size) a pivot may lie from a body's surface, and two bodies
/// of an interface overlap, before it is reported: far above round-off and an annular sector's
/// chords at the pivots (its corners are vertices), far below a typing error's metres.
pub const ON_SURFACE: f64 = 1e-4;

/// The warnings for the interfaces of `model` whose pivots lie off one of their bodies, or whose
/// bodies overlap at rest, one per interface (the farthest pivot, or the overlap's depth).
pub fn contact_geometry_warnings(model: &Model) -> Vec<String> {
    let tolerance = ON_SURFACE * model.size;
    let surfaces: Vec<Option<Surface>> = model
        .bodies
        .iter()
        .map(|b| b.shape.surface().ok())
        .collect();
    let mut out = Vec::new();
    for (index, iface) in model.interfaces.iter().enumerate() {
        if ContactFace::is_pin(model, index) {
            continue;
        }
        let child = Some(iface.child);
        let parent = match iface.parent {
            Parent::Body(b) => Some(b),
            Parent::Ground => None,
        };
        let farthest = [child, parent]
            .into_iter()
            .flatten()
            .filter_map(|b| {
                let surface = surfaces[b].as_ref()?;
                pivot_points(&iface.kind, &model.bodies[b].com)
                    .into_iter()
                    .map(|candidates| {
                        candidates
                            .into_iter()
                            .map(|p| (distance_to_surface(surface, &p), p, b))
                            .min_by(|x, y| x.0.total_cmp(&y.0))
                            .expect("a pivot has a point")
                    })
                    .max_by(|x, y| x.0.total_cmp(&y.0))
            })
            .max_by(|x, y| x.0.total_cmp(&y.0));
        if let Some((distance, p, b)) = farthest.filter(|f| f.0 > tolerance) {
            out.push(format!(
                "interface \"{}\": its pivot at ({:.4}, {:.4}, {:.4}) m lies {:.4} m from the \
                 surface of body \"{}\": the joint does not sit where its bodies touch (a \
                 mistyped pivot or position?), and the multipliers and motion are those of that \
                 geometry",
                iface.name,
                p.x + 0.0,
                p.y + 0.0,
                p.z + 0.0,
                distance,
                model.bodies[b].name
            ));
            continue;
        }
        if let (Some(b), Some(a), Some(c)) = (
            parent,
            parent.and_then(|b| surfaces[b].as_ref()),
            surfaces[iface.child].as_ref(),
        ) && let Some(overlap) = interpenetration(a, c, tolerance)
        {
            out.push(format!(
                "interface \"{}\": bodies \"{}\" and \"{}\" overlap by {:.4} m at rest: blocks \
                 in contact touch along a face (a mistyped position?)",
                iface.name, model.bodies[b].name, model.bodies[iface.child].name, overlap.depth
            ));
        }
    }
    out
}

/// Largest upward part n·ẑ of a contact's normal (into the body it carries) that still counts as
/// a vertical face: round-off of a face built vertical, far below any wedge a mason cuts.
pub const VERTICAL_FACE: f64 = 1e-9;

/// The warnings for the bodies of `model` that no contact carries from below: every face they
/// touch is vertical (its normal into the body has no upward part above [`VERTICAL_FACE`]), and
/// no pin holds them. Their weight then rests on shear across those faces alone, which the
/// statics without sliding grants with no compression at all, and a clamping force between
/// the faces (a self-stress the rigid blocks never supply at rest) grants with any friction:
/// `crr check` would say such a stone "holds" where a dry-stone one falls. (A stone between two
/// piers with vertical faces and nothing under it, written with `crr assemble --all-contacts`:
/// an independent review, 2026-12-06.)
pub fn bodies_held_by_shear_alone(model: &Model) -> Vec<String> {
    let mut carried = vec![false; model.bodies.len()];
    for face in contact_faces(model) {
        let iface = &model.interfaces[face.interface];
        let parent = match iface.parent {
            Parent::Body(b) => Some(b),
            Parent::Ground => None,
        };
        // The normal points into the child; into the parent it is −n.
        if face.pin || face.normal.z > VERTICAL_FACE {
            carried[iface.child] = true;
        }
        if let Some(b) = parent
            && (face.pin || -face.normal.z > VERTICAL_FACE)
        {
            carried[b] = true;
        }
    }
    model
        .bodies
        .iter()
        .zip(carried)
        .filter(|(_, carried)| !carried)
        .map(|(body, _)| {
            format!(
                "body \"{}\": every contact it has is a vertical face (no support under it): its \
                 weight rests on shear across those faces alone, which the statics grant without \
                 sliding, or with friction by a clamping force the blocks at rest do not supply; \
                 a dry-stone block so placed falls, so its multipliers and its rest are those of \
                 a block glued or wedged in place",
                body.name
            )
        })
        .collect()
}

/// The pivots of an interface to find on a body whose centre of mass is `com`, each as the
/// points of which one must lie on the body: a hinge pivot line's point given and its point
/// nearest the centre, or each of a rocking base's corners.
fn pivot_points(kind: &InterfaceKind, com: &Vector3<f64>) -> Vec<Vec<Vector3<f64>>> {
    match kind {
        InterfaceKind::Hinge {
            axis,
            pivot_positive,
            pivot_negative,
        } => [pivot_positive, pivot_negative]
            .into_iter()
            .map(|p| vec![*p, p + axis * axis.dot(&(com - p))])
            .collect(),
        InterfaceKind::RockingBase { corners, .. } => corners.iter().map(|c| vec![*c]).collect(),
    }
}
