//! The static (activation) multiplier of a seated structure along a horizontal direction: the
//! smallest constant ground acceleration, as a fraction λ of g, at which the structure at rest
//! starts to move, and the mechanism it opens in.
//!
//! It is the engine's own uplift test ([`crr_impact::simulation::opening_mode`], the test a
//! simulation runs at every step from a seated state), asked at rest under a constant ground
//! acceleration a = λ g d and bisected on λ. So it applies to any structure (several mechanisms,
//! loops, DOF(2) > 1), where the one-DOF report of `crr check` (λ = U′(0)/|Q_h(0)|) applies only
//! to a single mechanism. With infinite friction and rigid contacts the loads that the structure
//! carries at rest form a convex set containing 0 (the static theorem of limit analysis: a load
//! is carried if an equilibrium with compressive contact forces exists, a convex condition), so
//! along a ray from 0 the structure holds on [0, λ) and moves beyond: the bisection is well posed.

use std::collections::BTreeMap;

use nalgebra::{DVector, Vector3};
use serde::Serialize;

use crr_dynamics::Dynamics;
use crr_dynamics::ground_motion::{Axis, ComponentSpec, ConstantSpec, GroundMotion, SignalSpec};
use crr_impact::simulation::opening_mode;
use crr_kinematics::{ActivePivots, Model, Side};

/// Largest multiplier searched (ground acceleration 10 g): a structure that holds beyond it is
/// reported as not opening.
pub const LAMBDA_MAX: f64 = 10.0;

/// Relative width of the final bracket of λ.
pub const LAMBDA_RTOL: f64 = 1e-12;

/// The static multiplier along one direction of the ground acceleration.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StaticMultiplier {
    /// Unit horizontal direction d of the ground acceleration (the inertial load on the bodies
    /// acts along −d).
    pub direction: [f64; 3],
    /// λ (in g): the structure at rest holds under a = λ′ g d for every λ′ < λ and opens beyond;
    /// `None` when it holds up to [`LAMBDA_MAX`].
    pub lambda: Option<f64>,
    /// The joints that open at λ (just above it), by coordinate or slot name, with the side of
    /// their pivot (`+` or `-`); empty when `lambda` is `None`.
    pub opening: BTreeMap<String, String>,
}

/// The static multiplier of `model` at rest along the horizontal unit direction `direction` (the
/// ground accelerates along +d). Errors name what is wrong with the direction.
pub fn static_multiplier(
    model: &Model,
    direction: Vector3<f64>,
) -> Result<StaticMultiplier, String> {
    let norm = direction.norm();
    if !(norm.is_finite() && norm > 0.0) {
        return Err(format!(
            "direction ({}, {}, {}) is not a non-zero finite vector",
            direction.x, direction.y, direction.z
        ));
    }
    let d = direction / norm;
    if d.z.abs() > 1e-12 {
        return Err(format!(
            "direction ({}, {}, {}) is not horizontal (z must be 0)",
            direction.x, direction.y, direction.z
        ));
    }
    let n = model.dof();
    let zero = DVector::zeros(n);
    let mut template = Dynamics::new(model, ActivePivots::uniform(model, Side::Positive));
    template.seated = (0..model.slot_count).collect();
    let opens = |lambda: f64| -> Result<Option<Vec<(usize, Side)>>, String> {
        let ground = constant_ground(d * (lambda * model.gravity))?;
        Ok(opening_mode(model, &ground, &template, 0.0, &zero, &zero))
    };
    let unopened = StaticMultiplier {
        direction: [d.x, d.y, d.z],
        lambda: None,
        opening: BTreeMap::new(),
    };
    if opens(0.0)?.is_some() {
        return Err("the structure does not hold at rest without ground motion".into());
    }
    // Bracket: λ doubles from 1/64 until the structure opens.
    let mut low = 0.0;
    let mut high = 1.0 / 64.0;
    let mut mode = loop {
        if let Some(mode) = opens(high)? {
            break mode;
        }
        if high >= LAMBDA_MAX {
            return Ok(unopened);
        }
        low = high;
        high = (2.0 * high).min(LAMBDA_MAX);
    };
    while high - low > LAMBDA_RTOL * high {
        let mid = 0.5 * (low + high);
        if mid <= low || mid >= high {
            break;
        }
        match opens(mid)? {
            Some(m) => {
                high = mid;
                mode = m;
            }
            None => low = mid,
        }
    }
    Ok(StaticMultiplier {
        direction: [d.x, d.y, d.z],
        lambda: Some(high),
        opening: mode
            .iter()
            .map(|&(slot, side)| {
                (
                    slot_name(model, slot),
                    match side {
                        Side::Positive => "+".to_string(),
                        Side::Negative => "-".to_string(),
                    },
                )
            })
            .collect(),
    })
}

/// The multipliers along ±x and ±y (the ground accelerating along each).
pub fn static_multipliers(model: &Model) -> Result<Vec<StaticMultiplier>, String> {
    [Vector3::x(), -Vector3::x(), Vector3::y(), -Vector3::y()]
        .into_iter()
        .map(|d| static_multiplier(model, d))
        .collect()
}

/// A ground motion with the constant horizontal acceleration `a` (m/s²).
fn constant_ground(a: Vector3<f64>) -> Result<GroundMotion, String> {
    let mut ground = GroundMotion::none();
    for (axis, value) in [(Axis::X, a.x), (Axis::Y, a.y)] {
        if value != 0.0 {
            let spec = ComponentSpec::new(SignalSpec::Constant(ConstantSpec { value }));
            ground = ground
                .with_component(axis, &spec, std::path::Path::new("."))
                .map_err(|e| e.to_string())?;
        }
    }
    Ok(ground)
}

/// The name of a pivot slot: its interface's name, with `.1`/`.2` for the tilts of a rocking base
/// (the names of `crr inspect`; a closure's slots are named like a tree interface's).
fn slot_name(model: &Model, slot: usize) -> String {
    model
        .interfaces
        .iter()
        .find(|i| i.slots.contains(&slot))
        .map(|i| {
            if i.slots.len() > 1 {
                format!("{}.{}", i.name, slot - i.slots.start + 1)
            } else {
                i.name.clone()
            }
        })
        .unwrap_or_else(|| format!("slot {slot}"))
}
