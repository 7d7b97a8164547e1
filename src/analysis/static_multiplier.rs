//! The static (collapse) multiplier of a structure at rest along a direction of the ground
//! acceleration: the smallest constant ground acceleration, as a fraction λ of g, at which the
//! structure at rest cannot stay in equilibrium, with the mechanism it opens in and the friction
//! the answer relies on.
//!
//! It is the static theorem of limit analysis posed on the contact faces
//! ([`crr_impact::statics`]): one linear program over the corner forces of every interface
//! (compressive, no sliding), whose dual is the mechanism. Its answer is global: it does not
//! depend on the order in which the model lists its bodies, interfaces or corners, and a
//! mirror-symmetric structure gives equal multipliers in mirrored directions. A mechanism in
//! which a block lifts off one of its supports (which the CRR chain does not represent) is
//! reported as such.

use std::collections::BTreeMap;

use nalgebra::Vector3;
use serde::Serialize;

use crate::analysis::simulation::Cancel;
use crr_impact::statics::{
    COUNTED_SETS, Collapse, Friction, Motion, StaticsError, StaticsOptions, Unexhausted,
    collapse_multiplier, exhaustive_sets_needed, hinges_out_of_plane, required_friction,
    state_friction,
};
use crr_kinematics::{Model, Side};

pub use crr_impact::statics::LAMBDA_MAX;

/// One interface that moves in the mechanism.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MechanismJoint {
    /// The interface's name.
    pub interface: String,
    /// `rocks` (about the points in `about`), `lifts_off` (every point separates: outside the CRR
    /// chain) or, with `--friction`, `slides`.
    pub motion: Motion,
    /// The contact points that stay closed while it turns (m, world at rest): a hinge's pivot
    /// line, a rocking base's corner or edge.
    pub about: Vec<[f64; 3]>,
    /// Relative angular velocity of the child on the parent in the mechanism (rad/s, scaled so
    /// that the fastest body moves at unit speed).
    pub rotation: [f64; 3],
}

/// The static multiplier along one direction of the ground acceleration.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StaticMultiplier {
    /// Unit direction d of the ground acceleration (the inertial load on the bodies acts along
    /// −d).
    pub direction: [f64; 3],
    /// λ (in g): the structure at rest holds under a = λ′ g d for every λ′ < λ and not beyond;
    /// `None` when it holds up to [`LAMBDA_MAX`].
    pub lambda: Option<f64>,
    /// The CRR angles that open at λ, by coordinate or slot name, with the side of their pivot
    /// (`+` or `-`); empty when `lambda` is `None`.
    pub opening: BTreeMap<String, String>,
    /// Every interface that moves in the mechanism.
    pub mechanism: Vec<MechanismJoint>,
    /// The smallest Coulomb friction coefficient with which λ is reached (the no-sliding answer
    /// relies on it), or where it holds up to [`LAMBDA_MAX`], with which it holds that far; for an answer of the search for joints that open and slide, the one its
    /// collapse state needs at the points it keeps in contact
    /// ([`crr_impact::statics::state_friction`]); `None` with `--friction`, along a planar
    /// model's hinge axis, and where no μ up to 1000 reaches λ (`friction_unbounded`).
    pub required_friction: Option<f64>,
    /// Whether no Coulomb μ up to 1000 brings the multiplier within 1e-6 of λ: the answer rests
    /// on shear across a joint whose compression vanishes at λ (a closure limit, approached only
    /// as μ grows without bound) or on a friction beyond any masonry's, so with real friction
    /// the structure slides or opens first (`crr check --friction μ` gives that multiplier).
    pub friction_unbounded: bool,
    /// For a planar model (every interface a hinge about one common unit axis a,
    /// [`Model::planar_axis`]): |d·a|, the part of the load along a, which the hinges carry
    /// bilaterally; `None` for any other model. Above 0, λ answers for the load's part in the
    /// plane of motion only (the in-plane multiplier is λ·√(1 − |d·a|²)); exactly 1 (d along a,
    /// to 1e-9 rad) the model says nothing and `lambda` is `None`: out-of-plane overturning or
    /// sliding is outside a planar model (a structure that does not stand under its own weight
    /// is an error there as along any direction).
    pub out_of_plane: Option<f64>,
    /// In a model that is not planar, the hinges that every distribution of the contact forces
    /// at λ (at λ_max where the structure holds) loads out of their plane, with a force along
    /// their axis or a couple not about it above 1e-6 of W or W·L (W the weight, L the model
    /// size; [`crr_impact::statics::hinges_out_of_plane`]): a hinge is a line that transmits
    /// those whatever they are, so λ relies on a capacity the model gives it without geometry
    /// (the out-of-plane width of the joint). Empty where some distribution spares them all.
    pub hinges_out_of_plane: Vec<String>,
    /// The convex program's λ, where `lambda` lies below it: `lambda` is then the search's
    /// answer for joints that open and slide, an admissible mechanism (the structure does not
    /// hold beyond it) from a search that is not exhaustive, so a lower one may exist. `None`
    /// where `lambda` is the convex program's own answer (exact for joints that do not slide),
    /// and where the convex program holds up to the cap (`from_sliding_search` then says).
    pub convex_lambda: Option<f64>,
    /// Whether `lambda` comes from the search for joints that open and slide, below the convex
    /// program's answer (`convex_lambda`, or holding up to the cap where that is `None`).
    pub from_sliding_search: bool,
    /// Whether `lambda` is the least over every collapse state of the contact model, joints that
    /// open and slide included ([`crr_impact::statics::Collapse::exhaustive`]): a structure
    /// without loops, or one whose sets of joints that may open and slide were all tried.
    /// `false`: not every set was tried (`not_exhaustive_because` says why), so `lambda` is the
    /// search's answer, an upper bound of the multiplier (a lower mechanism may exist). Always
    /// with `--friction`.
    pub exhaustive: bool,
    /// Why `exhaustive` is false: `too_many_sets` (more sets of joints that may open and slide
    /// than the budget, [`MultiplierOptions::exhaustive_sets`]) or `{"solver_failed":
    /// status}` (a program of the exhaustive pass did not solve); `None` where it is true.
    pub not_exhaustive_because: Option<crr_impact::statics::Unexhausted>,
    /// Where `not_exhaustive_because` is `too_many_sets`: how many sets the exhaustive pass
    /// would try along this direction (counted without a program,
    /// [`crr_impact::statics::exhaustive_sets_needed`]), the `exhaustive_sets` that makes the
    /// answer exhaustive; `None` beyond [`crr_impact::statics::COUNTED_SETS`] and wherever
    /// there is no such reason.
    pub exhaustive_sets_needed: Option<usize>,
}

/// What the static multipliers are asked with.
#[derive(Debug, Clone, PartialEq)]
pub struct MultiplierOptions {
    /// Coulomb friction μ at every contact point (the exact cone ‖(f₁, f₂)‖ ≤ μ fₙ; a hinge's
    /// in its plane); `None`: no sliding, and the report gives the friction each multiplier
    /// needs.
    pub friction: Option<f64>,
    /// The most sets of joints that may open and slide the exhaustive pass tries per direction
    /// ([`crr_impact::statics::StaticsOptions::exhaustive_sets`]); beyond them λ is the
    /// search's answer, an upper bound.
    pub exhaustive_sets: usize,
    /// A request to stop: once set, the statics stop after the linear program under way and
    /// [`static_multiplier_with`] answers [`INTERRUPTED`] (the search and the exhaustive pass
    /// solve hundreds to thousands of programs on a wall).
    pub cancel: Option<Cancel>,
}

/// The error of a multiplier whose [`MultiplierOptions::cancel`] was set.
pub const INTERRUPTED: &str = "interrupted";

impl Default for MultiplierOptions {
    fn default() -> Self {
        MultiplierOptions {
            friction: None,
            exhaustive_sets: crr_impact::statics::EXHAUSTIVE_SETS,
            cancel: None,
        }
    }
}

/// What the program without sliding answered, for the reports of an answer the search for
/// joints that open and slide found below it: "λ = 1.250000", or "it holds up to λ = 10".
pub fn without_sliding(convex_lambda: Option<f64>) -> String {
    match convex_lambda {
        Some(convex) => format!("λ = {convex:.6}"),
        None => format!("it holds up to λ = {LAMBDA_MAX}"),
    }
}

impl StaticMultiplier {
    /// Whether the mechanism lifts a block off a support (outside the CRR chain).
    pub fn lifts_off(&self) -> bool {
        self.mechanism.iter().any(|j| j.motion == Motion::LiftsOff)
    }
}

/// The static multiplier of `model` at rest along the unit direction `direction` (the ground
/// accelerates along +d; d may have a vertical part), without sliding. Errors name what is wrong
/// with the direction or why the structure has no multiplier.
pub fn static_multiplier(
    model: &Model,
    direction: Vector3<f64>,
) -> Result<StaticMultiplier, String> {
    static_multiplier_with(model, direction, &MultiplierOptions::default())
}

/// [`static_multiplier`] with the options `asked`: Coulomb friction μ at every contact point
/// instead of no sliding (`required_friction` is then `None`), and the budget of the exhaustive
/// pass.
pub fn static_multiplier_with(
    model: &Model,
    direction: Vector3<f64>,
    asked: &MultiplierOptions,
) -> Result<StaticMultiplier, String> {
    let friction = asked.friction;
    let options = StaticsOptions {
        friction: friction.map_or(Friction::NoSliding, Friction::Cone),
        exhaustive_sets: asked.exhaustive_sets,
        cancel: asked.cancel.clone(),
        ..StaticsOptions::default()
    };
    let cancelled = || asked.cancel.as_ref().is_some_and(Cancel::is_cancelled);
    let along_axis = out_of_plane(model, &direction);
    if along_axis == Some(1.0) {
        // Along a planar model's hinge axis the hinges hold any load, so there is no multiplier
        // to report; the program still runs, because the load along the axis leaves the in-plane
        // equilibrium as it is under gravity alone, and one that does not stand at rest must say
        // so here as along ±x (the program has no solution for any λ then).
        // Only that verdict is kept: the program along the axis is degenerate (every λ or
        // none), and a solver's trouble with it must not hide the in-plane answers.
        if let Err(e @ StaticsError::DoesNotHold(_)) =
            collapse_multiplier(model, direction, &options)
        {
            return Err(e.to_string());
        }
        return Ok(StaticMultiplier {
            // + 0.0: −0.0 components print as 0.0, as the statics' own directions do.
            direction: direction.normalize().map(|x| x + 0.0).into(),
            lambda: None,
            opening: BTreeMap::new(),
            mechanism: Vec::new(),
            required_friction: None,
            friction_unbounded: false,
            out_of_plane: along_axis,
            hinges_out_of_plane: Vec::new(),
            convex_lambda: None,
            from_sliding_search: false,
            exhaustive: true,
            not_exhaustive_because: None,
            exhaustive_sets_needed: None,
        });
    }
    let collapse = collapse_multiplier(model, direction, &options).map_err(|e| e.to_string())?;
    // The friction's and the hinges' programs take no request to stop: a few programs each.
    if cancelled() {
        return Err(INTERRUPTED.into());
    }
    // The friction the answer relies on: for a collapse state of the search for joints that
    // open and slide, that of its own holding points (more than the convex program's).
    let required = match (collapse.lambda, friction) {
        (Some(_), None) if collapse.from_sliding_search() => {
            state_friction(model, &collapse, options.lambda_max).map_err(|e| e.to_string())?
        }
        (Some(lambda), None) => Some(
            required_friction(model, direction, options.lambda_max, lambda)
                .map_err(|e| e.to_string())?,
        ),
        // Holding up to the cap without sliding relies on friction too (a slab ten times as
        // wide as it is high holds to 10 g only with μ ≥ 10).
        // A solver's trouble with this secondary answer leaves it out rather than the
        // multiplier.
        (None, None) => {
            required_friction(model, direction, options.lambda_max, options.lambda_max).ok()
        }
        _ => None,
    };
    // With friction μ: a collapse state found without sliding whose own friction is within μ is
    // a collapse state with μ too, and where it is lower it is the answer (the convex program
    // with friction, without the search, answered up to 48 % above it on the bundled wall). On
    // a tree (an exhaustive answer) the convex program is exact and the two agree.
    if let Some(mu) = friction
        && !collapse.exhaustive
    {
        let plain = static_multiplier_with(
            model,
            direction,
            &MultiplierOptions {
                friction: None,
                ..asked.clone()
            },
        )?;
        let covered = plain.required_friction.is_some_and(|need| need <= mu);
        let lower = match (plain.lambda, collapse.lambda) {
            (Some(l0), Some(l)) => l0 < l,
            (Some(_), None) => true,
            _ => false,
        };
        if covered && lower {
            return Ok(plain);
        }
    }
    let mut report = report(model, &collapse, required);
    if collapse.unexhausted == Some(Unexhausted::TooManySets) {
        report.exhaustive_sets_needed = exhaustive_sets_needed(model, &collapse, COUNTED_SETS);
    }
    // A planar model's out-of-plane part is `out_of_plane`; elsewhere the hinges that every
    // distribution at λ loads out of their plane (at λ_max where it holds).
    if model.planar_axis().is_none() {
        let at = collapse.lambda.unwrap_or(options.lambda_max);
        report.hinges_out_of_plane = hinges_out_of_plane(model, direction, &options, at)
            .map_err(|e| e.to_string())?
            .into_iter()
            .map(|h| h.name)
            .collect();
    }
    Ok(report)
}

/// The largest Coulomb friction coefficient the statics take (`crr check --friction`, Python's
/// `Model.check(friction=…)`): above it their programs lose their accuracy (1e300 ended in a
/// solver's NumericalError), and it is also the largest need for friction they report.
pub const MAX_FRICTION: f64 = 1e3;

/// μ as the statics take it: a number from 0 to [`MAX_FRICTION`], else why not.
pub fn check_friction(mu: f64) -> Result<f64, String> {
    if mu.is_finite() && (0.0..=MAX_FRICTION).contains(&mu) {
        Ok(mu)
    } else {
        Err(format!(
            "must be a number from 0 to 1000 (no masonry joint needs more to hold), got {mu}"
        ))
    }
}

/// A direction of the ground acceleration from the command line: `+x`, `-x`, `+y`, `-y`, `+z`,
/// `-z` (or without the `+`), or three numbers `X,Y,Z`, not all zero.
pub fn parse_direction(text: &str) -> Result<Vector3<f64>, String> {
    let named = match text.trim() {
        "+x" | "x" => Some(Vector3::x()),
        "-x" | "−x" => Some(-Vector3::x()),
        "+y" | "y" => Some(Vector3::y()),
        "-y" | "−y" => Some(-Vector3::y()),
        "+z" | "z" => Some(Vector3::z()),
        "-z" | "−z" => Some(-Vector3::z()),
        _ => None,
    };
    if let Some(d) = named {
        return Ok(d);
    }
    let parts: Vec<&str> = text.split(',').collect();
    if parts.len() != 3 {
        return Err(format!(
            "'{text}' is neither ±x, ±y, ±z nor three numbers X,Y,Z"
        ));
    }
    let mut d = Vector3::zeros();
    for (k, p) in parts.iter().enumerate() {
        d[k] = p
            .trim()
            .parse::<f64>()
            .map_err(|_| format!("'{}' in '{text}' is not a number", p.trim()))?;
        // Rust reads "nan" and "inf" as numbers; a direction has neither.
        if !d[k].is_finite() {
            return Err(format!("'{}' in '{text}' is not a finite number", p.trim()));
        }
    }
    // Only the direction counts: scaled by its largest component, a vector of tiny or huge
    // components (1e-300, 1e300) is one, whose norm alone would underflow or overflow.
    let largest = d.amax();
    if !(largest.is_finite() && largest > 0.0) {
        return Err(format!("'{text}' is not a non-zero finite vector"));
    }
    Ok(d / largest)
}

/// The four horizontal directions ±x, ±y.
pub fn horizontal_directions() -> Vec<Vector3<f64>> {
    vec![Vector3::x(), -Vector3::x(), Vector3::y(), -Vector3::y()]
}

/// The multipliers along ±x and ±y (the ground accelerating along each).
pub fn static_multipliers(model: &Model) -> Result<Vec<StaticMultiplier>, String> {
    horizontal_directions()
        .into_iter()
        .map(|d| static_multiplier(model, d))
        .collect()
}

/// For a planar model (common hinge axis a), the part |d̂·a| of `direction` (unit d̂) along a,
/// which its hinges carry bilaterally: exactly 0 within 1e-12 of the plane and exactly 1 within
/// 1e-9 rad of the axis (the rule [`Model::planar_axis`] applies to the hinges' own axes). None
/// for a model that is not planar; Some(0.0) for a zero or non-finite direction (which the
/// statics refuses).
pub fn out_of_plane(model: &Model, direction: &Vector3<f64>) -> Option<f64> {
    let a = model.planar_axis()?;
    let norm = direction.norm();
    if !(norm.is_finite() && norm > 0.0) {
        return Some(0.0);
    }
    let d = direction / norm;
    let part = a.dot(&d).abs().min(1.0);
    Some(if a.cross(&d).norm() < 1e-9 {
        1.0
    } else if part < 1e-12 {
        0.0
    } else {
        part
    })
}

/// For a planar model whose common axis a is not horizontal, the part |a·ẑ| of gravity along a
/// (the sine of the axis' angle to the horizontal): its hinges carry g|a·ẑ| per unit mass
/// bilaterally, and the bodies move under g√(1 − (a·ẑ)²) in their plane. None for a model that
/// is not planar or whose axis is horizontal to within 1e-9 rad (the rule of
/// [`Model::planar_axis`]).
pub fn gravity_along_axis(model: &Model) -> Option<f64> {
    let a = model.planar_axis()?;
    let part = a.z.abs().min(1.0);
    (part > 1e-9).then_some(part)
}

/// The warning of `crr check` and `crr simulate` for a planar model whose axis is not
/// horizontal ([`gravity_along_axis`]), else None.
pub fn gravity_along_axis_warning(model: &Model) -> Option<String> {
    let part = gravity_along_axis(model)?;
    let a = model.planar_axis()?;
    Some(format!(
        "the hinges' common axis ({:.3}, {:.3}, {:.3}) is {:.1}° from the horizontal: the hinges \
         of a planar model carry the part of gravity along it ({:.4} g) bilaterally, and the \
         structure rocks under the rest ({:.4} g) in the plane normal to the axis; a real \
         structure on joints so inclined could also slide or overturn along the axis, which is \
         outside the model",
        a.x + 0.0,
        a.y + 0.0,
        a.z + 0.0,
        part.asin().to_degrees(),
        part,
        (1.0 - part * part).sqrt()
    ))
}

/// The report of one collapse; `friction` is the μ it relies on, infinite beyond 1000.
fn report(model: &Model, collapse: &Collapse, friction: Option<f64>) -> StaticMultiplier {
    let moving = || {
        collapse
            .interfaces
            .iter()
            .filter(|i| i.motion != Motion::Closed)
    };
    let opening = moving()
        .filter(|i| i.motion == Motion::Rocks)
        .flat_map(|i| i.sides.iter())
        .map(|&(slot, side)| {
            (
                model.slot_name(slot),
                match side {
                    Side::Positive => "+".to_string(),
                    Side::Negative => "-".to_string(),
                },
            )
        })
        .collect();
    let mechanism = moving()
        .map(|i| MechanismJoint {
            interface: i.name.clone(),
            motion: i.motion.clone(),
            about: i.pivots.iter().map(|&p| i.forces[p].point).collect(),
            rotation: i.rotation,
        })
        .collect();
    StaticMultiplier {
        direction: collapse.direction,
        lambda: collapse.lambda,
        opening,
        mechanism,
        // JSON has no infinity (serde writes null): the unbounded case is a flag of its own.
        required_friction: friction.filter(|mu| mu.is_finite()),
        friction_unbounded: friction.is_some_and(f64::is_infinite),
        out_of_plane: out_of_plane(model, &Vector3::from(collapse.direction)),
        hinges_out_of_plane: Vec::new(),
        convex_lambda: collapse
            .from_sliding_search()
            .then_some(collapse.convex_lambda)
            .flatten(),
        from_sliding_search: collapse.from_sliding_search(),
        exhaustive: collapse.exhaustive,
        not_exhaustive_because: collapse.unexhausted.clone(),
        exhaustive_sets_needed: None,
    }
}
