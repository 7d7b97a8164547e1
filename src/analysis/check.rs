//! `crr check`: the mobility report of a model and, for a one-DOF mechanism, its activation
//! multiplier, equivalent single block, coefficient of restitution and free-rocking frequencies
//! (keys documented in `docs/outputs.md`).

use std::collections::BTreeMap;

use nalgebra::{DVector, Vector3};
use serde::Serialize;

use crr_dynamics::ground_motion::GroundMotion;
use crr_dynamics::mechanism::reduce_at;
use crr_dynamics::{
    FiniteMobility, InitialSpec, LagrangianParameters, Mobility, horizontal_direction,
    lagrangian_parameters_on_side, mobility, mobility_after_step, reported_side, solve_initial,
};
use crr_impact::laws::momentum_law;
use crr_impact::simulation::{Parameters, Simulation, StopReason};
use crr_kinematics::{ActivePivots, Data, Model, Side};

use crate::analysis::static_multiplier::{
    MultiplierOptions, StaticMultiplier, horizontal_directions, static_multiplier_with,
};

/// One line of the frequency table.
#[derive(Clone, Debug, Serialize)]
pub struct FrequencyRow {
    /// θ_m/α_eq.
    pub amplitude_ratio: f64,
    /// θ_m (rad): the released angle of the mechanism coordinate (negative on the side `-`).
    pub theta_m: f64,
    /// F_H = √χ / (4 arccosh(1/(1 − εθ_m))), χ = p_eq², ε = 1/α_eq (Hz).
    pub housner_hz: f64,
    /// 1/(4τ) with τ the time of the engine's first fall from θ_m to 0 (Hz); None if it did not
    /// return to 0 (or the run failed).
    pub engine_hz: Option<f64>,
    /// engine_hz / housner_hz.
    pub ratio: Option<f64>,
}

/// The one-DOF mechanism seen as a single block.
#[derive(Clone, Debug, Serialize)]
pub struct MechanismReport {
    /// The mechanism coordinate θ (the first coordinate).
    pub coordinate: String,
    /// The side the mechanism opens on, `+` (θ > 0) or `-` (θ < 0): the one that opens under
    /// its own weight, else the smaller λ, else (equal λ) the larger α_eq, else `+`
    /// ([`crr_dynamics::reported_side`]). Every quantity below is read in the opening angle
    /// |θ| of that side.
    pub side: String,
    /// Unit horizontal direction of the ground acceleration used for λ (perpendicular to the
    /// coordinate's axis).
    pub direction: [f64; 3],
    /// Pivot side of every angle slot in the opening state of `side` (`+` or `-`), by interface name
    /// (joined by `/` for a rocking base).
    pub pivots: BTreeMap<String, String>,
    /// λ: activating ground acceleration in g (limit-analysis collapse multiplier).
    pub lambda: f64,
    /// Sign of the activating acceleration along `direction`.
    pub lambda_sign: f64,
    /// M(0) = Bᵀ M B (kg m²).
    pub mass: f64,
    /// U′(0) (N m).
    pub potential_slope: f64,
    /// U″(0) (N m).
    pub potential_curvature: f64,
    /// α_eq (rad).
    pub alpha_eq: f64,
    /// p_eq = √(√(U′² + U″²)/M(0)) (rad/s).
    pub p_eq: f64,
    /// p_eq² (1/s²).
    pub p_squared: f64,
    /// −U″(0)/M(0) (1/s²).
    pub p_squared_linearised: f64,
    /// r = θ̇⁺/θ̇⁻ of the momentum law at θ = 0 for the mechanism velocity, pivots flipped.
    pub r: f64,
    /// T⁺/T⁻ of that impact: 0 where the mechanism seats at it ([`seats_at_impact`]).
    pub energy_ratio: f64,
    /// max |q̇⁺ − r q̇⁻| / max |q̇⁻|: how far the velocity after the impact is from a multiple of
    /// the velocity before (0 for a symmetric mechanism).
    pub mode_change: f64,
    /// The paper's one-DOF Lagrangian (eq 4): ν, ξ, η, χ, and eq 6's χ and ε (NOTATION.md).
    pub lagrangian: LagrangianParameters,
    /// Generalized Housner frequency against the engine's free rocking.
    pub frequencies: Vec<FrequencyRow>,
}

/// Everything `crr check` reports.
#[derive(Clone, Debug, Serialize)]
pub struct CheckReport {
    /// Model name.
    pub model: String,
    /// g (m/s²).
    pub gravity: f64,
    /// Coordinate names, in the order of q.
    pub coordinates: Vec<String>,
    /// Loop-closing interfaces.
    pub closures: Vec<String>,
    /// The mobility at rest (q = 0, every pivot `+`).
    pub mobility: Mobility,
    /// DOF(2) after a finite step along the mechanism (closed chains that can move; `None`
    /// otherwise). Smaller than at rest when the loops only close to first order.
    pub finite_mobility: Option<FiniteMobility>,
    /// Why `finite_mobility` is missing for a closed chain that can move.
    pub finite_mobility_note: Option<String>,
    /// Present when DOF(2) = 1.
    pub mechanism: Option<MechanismReport>,
    /// Why the mechanism part is missing or incomplete.
    pub note: Option<String>,
    /// The static multipliers of the structure at rest along +x, −x, +y and −y
    /// ([`crate::analysis::static_multiplier`]): any structure, whatever its DOF(2); empty when the search
    /// failed (`static_multipliers_note` says why).
    pub static_multipliers: Vec<StaticMultiplier>,
    /// Why `static_multipliers` is empty, else `None`.
    pub static_multipliers_note: Option<String>,
    /// The most sets of joints that may open and slide the exhaustive pass tried per direction
    /// (`crr check --exhaustive-sets`, default [`crr_impact::statics::EXHAUSTIVE_SETS`]).
    pub exhaustive_sets: usize,
    /// What to know before trusting the report (a planar model whose hinge axis is not
    /// horizontal, [`crate::analysis::static_multiplier::gravity_along_axis_warning`]).
    pub warnings: Vec<String>,
}

/// Housner's linearised frequency (Hz) at amplitude θ_m.
pub fn housner_frequency(p: f64, alpha: f64, theta_m: f64) -> f64 {
    p / (4.0 * (1.0 / (1.0 - theta_m / alpha)).acosh())
}

/// The time of the first return of the mechanism to θ = 0 after release from θ_m at rest.
pub fn first_fall_time(model: &Model, coordinate: &str, theta_m: f64, limit: f64) -> Option<f64> {
    let spec = InitialSpec {
        angles: [(coordinate.to_string(), theta_m)].into_iter().collect(),
        rates: BTreeMap::new(),
    };
    let initial = solve_initial(model, &spec).ok()?;
    let ground = GroundMotion::none();
    let params = Parameters {
        duration: limit,
        output_interval: limit / 4.0,
        ..Parameters::default()
    };
    let mut sim = Simulation::new(model, &ground, &initial, params).ok()?;
    loop {
        match sim.step().ok()? {
            StopReason::Impact(i) => return Some(sim.impacts[i].t),
            StopReason::End(_) | StopReason::Collapse(_) => return None,
            _ => {}
        }
    }
}

fn slot_codes(model: &Model, pivots: &ActivePivots) -> BTreeMap<String, String> {
    model
        .interfaces
        .iter()
        .map(|i| {
            let codes: Vec<&str> = i
                .slots
                .clone()
                .map(|s| match pivots.sides[s] {
                    Side::Positive => "+",
                    Side::Negative => "-",
                })
                .collect();
            (i.name.clone(), codes.join("/"))
        })
        .collect()
}

fn mechanism(model: &Model) -> Result<MechanismReport, String> {
    let name = model.coords[0].name.clone();
    let d = horizontal_direction(model, 0);
    // The side the mechanism is reported on follows from its physics, not from the sense the
    // file gives the coordinate (reported_side).
    let (side, pivots, eq) = reported_side(model, 0, &d).map_err(|e| e.to_string())?;
    let sigma = side.sign();
    let lagrangian =
        lagrangian_parameters_on_side(model, &pivots, 0, &d, side).map_err(|e| e.to_string())?;
    // r from the momentum law: closing velocity on the opening pivots, after the flip.
    let zero = DVector::zeros(model.dof());
    let b = reduce_at(model, &zero, &pivots, 0, &d)
        .map_err(|e| e.to_string())?
        .velocity_map;
    let before = pivots.clone();
    let after = ActivePivots {
        sides: before.sides.iter().map(|s| s.flipped()).collect(),
    };
    // Closing: the coordinate turns back towards 0 from the side it opened on.
    let qd = &b * -sigma;
    let mut kin = Data::new(model);
    let res = momentum_law(model, &mut kin, &zero, &qd, &before, &after)
        .map_err(|e| format!("momentum law: {e}"))?;
    let r = res.qdot[0] / qd[0];
    let mode_change = (&res.qdot - &qd * r).amax() / qd.amax();
    let p = eq.p_squared.sqrt();
    let alpha = eq.alpha;
    let frequencies = (1..=9)
        .map(|k| {
            let ratio = k as f64 / 10.0;
            let amplitude = ratio * alpha;
            let fh = housner_frequency(p, alpha, amplitude);
            let limit = 2.0 / fh + 1.0;
            let theta_m = sigma * amplitude;
            let engine = first_fall_time(model, &name, theta_m, limit).map(|tau| 1.0 / (4.0 * tau));
            FrequencyRow {
                amplitude_ratio: ratio,
                theta_m,
                housner_hz: fh,
                engine_hz: engine,
                ratio: engine.map(|e| e / fh),
            }
        })
        .collect();
    Ok(MechanismReport {
        coordinate: name,
        side: if sigma > 0.0 { "+" } else { "-" }.to_string(),
        direction: [d.x, d.y, d.z],
        pivots: slot_codes(model, &pivots),
        lambda: eq.lambda,
        lambda_sign: eq.lambda_sign,
        mass: eq.mass,
        potential_slope: eq.potential_slope,
        potential_curvature: eq.potential_curvature,
        alpha_eq: alpha,
        p_eq: p,
        p_squared: eq.p_squared,
        p_squared_linearised: eq.p_squared_linearised,
        r,
        energy_ratio: if seats_at_impact(r, mode_change) {
            0.0
        } else {
            res.energy_ratio()
        },
        mode_change,
        lagrangian,
        frequencies,
    })
}

/// Largest angle (rad) of the step along the mechanism used for the finite-mobility check.
pub const FINITE_STEP: f64 = 0.01;

/// Builds the report, with the static multipliers along ±x and ±y without sliding.
pub fn check(model: &Model) -> CheckReport {
    match check_with(
        model,
        &horizontal_directions(),
        &MultiplierOptions::default(),
    ) {
        Ok(report) => report,
        Err(CheckInterrupted) => unreachable!("a check without a request to stop runs through"),
    }
}

/// A check stopped by its request to stop ([`MultiplierOptions::cancel`]): it has no report.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("the check was interrupted")]
pub struct CheckInterrupted;

/// Builds the report, with the static multipliers along `directions` (unit or not; the ground
/// accelerating along each), asked with `asked` (friction, the exhaustive pass's budget, a
/// request to stop). Once `asked.cancel` is set the check stops after the stage under way (the
/// mobility's factorisation, the finite step, the one-DOF mechanism, or one linear program of
/// the statics) and answers [`CheckInterrupted`].
pub fn check_with(
    model: &Model,
    directions: &[Vector3<f64>],
    asked: &MultiplierOptions,
) -> Result<CheckReport, CheckInterrupted> {
    let go_on = || match &asked.cancel {
        Some(cancel) if cancel.is_cancelled() => Err(CheckInterrupted),
        _ => Ok(()),
    };
    go_on()?;
    let zero = DVector::zeros(model.dof());
    let mob = mobility(model, &zero, &ActivePivots::uniform(model, Side::Positive));
    go_on()?;
    let (finite, finite_note) = if model.closure_rows > 0 && !mob.locked {
        match mobility_after_step(model, FINITE_STEP) {
            Ok(f) => (Some(f), None),
            Err(e) => (None, Some(format!("not evaluated: {e}"))),
        }
    } else {
        (None, None)
    };
    go_on()?;
    let (mech, note) = if mob.dof2 == 1 {
        match mechanism(model) {
            Ok(m) => (Some(m), None),
            Err(e) => (
                None,
                Some(format!("one-DOF mechanism analysis failed: {e}")),
            ),
        }
    } else if mob.locked {
        (
            None,
            Some(
                "locked: DOF(2) = 0, the CRR chain cannot move with every joint seated; the \
                 structure can still move where a joint opens (the static multipliers below)"
                    .into(),
            ),
        )
    } else {
        (
            None,
            Some(format!(
                "DOF(2) = {}: no single equivalent block (only one-DOF mechanisms are reduced)",
                mob.dof2
            )),
        )
    };
    // The statics run on the contact faces whatever the CRR chain's mobility: a chain locked by
    // its hinges can still open by a block lifting off a support. The directions are
    // independent, each on its own thread (the search for joints that open and slide can run
    // hundreds of programs along one); the first error in the directions' order is reported.
    let statics = std::thread::scope(|scope| {
        let handles: Vec<_> = directions
            .iter()
            .map(|&d| scope.spawn(move || static_multiplier_with(model, d, asked)))
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
            .collect::<Result<Vec<_>, _>>()
    });
    // An interrupted direction answers an error, and one that ran through may have run past
    // the request: neither is reported.
    go_on()?;
    let (statics, statics_note) = match statics {
        Ok(v) => (v, None),
        Err(e) => (Vec::new(), Some(e)),
    };
    Ok(CheckReport {
        model: model.name.clone(),
        gravity: model.gravity,
        coordinates: model.coords.iter().map(|c| c.name.clone()).collect(),
        closures: model
            .closures
            .iter()
            .map(|c| model.interfaces[c.interface].name.clone())
            .collect(),
        mobility: mob,
        finite_mobility: finite,
        finite_mobility_note: finite_note,
        mechanism: mech,
        note,
        static_multipliers: statics,
        static_multipliers_note: statics_note,
        exhaustive_sets: asked.exhaustive_sets,
        warnings: crate::analysis::static_multiplier::gravity_along_axis_warning(model)
            .into_iter()
            .chain(crate::analysis::contact_geometry::contact_geometry_warnings(model))
            .chain(crate::analysis::contact_geometry::bodies_held_by_shear_alone(model))
            .chain(crate::analysis::body_sizes::bodies_too_large(model))
            .collect(),
    })
}

/// The lines of a multiplier's report on joints that open and slide: where λ comes from them,
/// and whether every set of them was tried (docs/simulation.md, "Joints that open may slide").
fn sliding_note(m: &crate::analysis::static_multiplier::StaticMultiplier, budget: usize) -> String {
    let see = "(docs/simulation.md, \"Joints that open may slide\")";
    let without = crate::analysis::static_multiplier::without_sliding(m.convex_lambda);
    let why = match &m.not_exhaustive_because {
        Some(crr_impact::statics::Unexhausted::SolverFailed(status)) => format!(
            "a program of the pass over the sets of joints that may open and slide did not solve ({status}), so not every set was tried"
        ),
        Some(crr_impact::statics::Unexhausted::WithFriction) => "with Coulomb friction the \
            statics solve the convex program alone, the search for joints that open and slide \
            running without sliding (its answer is taken where the friction asked covers it)"
            .to_string(),
        _ => match m.exhaustive_sets_needed {
            Some(needed) => format!(
                "the structure's loops give {needed} sets of joints that may open and slide, more than the statics try ({budget}): `crr check --exhaustive-sets {needed}` tries them all, at one to three linear programs a set"
            ),
            None => format!(
                "the structure's loops give more than {} sets of joints that may open and slide, and the statics try {budget}",
                crr_impact::statics::COUNTED_SETS
            ),
        },
    };
    match (m.from_sliding_search, m.exhaustive) {
        (true, true) => format!(
            "    found among the joints that open and slide (without them {without}): a mechanism with an equilibrium on the contacts it keeps exists at this λ, and every set of joints that may open and slide was tried, so none opens lower {see}\n"
        ),
        (true, false) => format!(
            "    found by the search for joints that open and slide (without them {without}): a mechanism with an equilibrium on the contacts it keeps exists at this λ, so the structure can move from it on, but the search is not exhaustive ({why}) and a lower mechanism may exist {see}\n"
        ),
        (false, false) => format!(
            "    not exhaustive: {why}, and the search found none lower; this λ is an upper bound and a lower mechanism may exist {see}\n"
        ),
        (false, true) => String::new(),
    }
}

/// The report as text.
pub fn to_text(r: &CheckReport) -> String {
    let m = &r.mobility;
    let mut s = format!("model: {}\n", r.model);
    for w in &r.warnings {
        s += &format!("warning: {w}\n");
    }
    s += &format!(
        "DOF(1) = {} (coordinates: {})\n",
        m.dof1,
        r.coordinates.join(", ")
    );
    s += &format!(
        "loop closures: {} ({}), {} rows of Φ, rank {} ({} redundant)\n",
        m.closures,
        if r.closures.is_empty() {
            "none".to_string()
        } else {
            r.closures.join(", ")
        },
        m.constraint_rows,
        m.rank,
        m.redundant
    );
    s += &format!(
        "DOF(2) = {}{}\n",
        m.dof2,
        if m.locked { " (locked)" } else { "" }
    );
    if m.dof2_at_precision != m.dof2 {
        s += &format!(
            "DOF(2) at the model's precision = {}: Φ_q has {} singular value(s) between 1e-9 \
             and {:.0e} of its largest, so its loops close only to the round-off of its geometry \
             (coordinates with few decimals, or far from the origin). The dynamics follows the \
             loops as written (DOF(2) = {}); written with more decimals, or nearer the origin, \
             they move as meant\n",
            m.dof2_at_precision,
            m.dof2_at_precision - m.dof2,
            crr_dynamics::closed_chain::PRECISION_RANK_TOLERANCE,
            m.dof2
        );
    }
    if let Some(f) = &r.finite_mobility {
        s += &format!(
            "DOF(2) after a {} rad step along the mechanism = {}\n",
            f.step, f.dof2
        );
        if f.dof2 < m.dof2 {
            s += &format!(
                "  the loops move only to first order at rest: {} of the {} independent motions at rest \
                 have no finite continuation. Followed further, they would turn a \
                 rocking base about its contact normal (a twist, which a rocking base \
                 forbids) or pull a loop apart; the structure can only start along them. \
                 Near rest its constrained solve is ill-conditioned. Where the order of a \
                 rocking base's two tilts causes it, reorder its corners \
                 (docs/model-format.md, rocking bases in loops)\n",
                m.dof2 - f.dof2,
                m.dof2
            );
        }
    }
    if let Some(note) = &r.finite_mobility_note {
        s += &format!("DOF(2) after a finite step along the mechanism: {note}\n");
    }
    if m.symmetries > 0 {
        s += &format!("symmetries: {}, DOF(3) = {}\n", m.symmetries, m.dof3);
    }
    if let Some(note) = &r.note {
        s += &format!("note: {note}\n");
    }
    if !r.static_multipliers.is_empty() {
        s += "static multiplier at rest (constant ground acceleration λ g along d; limit analysis on the contact faces; \
              the friction λ needs; the joints that open):\n";
        for m in &r.static_multipliers {
            let d = m.direction;
            let dir = if d == [1.0, 0.0, 0.0] {
                "+x".to_string()
            } else if d == [-1.0, 0.0, 0.0] {
                "−x".to_string()
            } else if d == [0.0, 1.0, 0.0] {
                "+y".to_string()
            } else if d == [0.0, -1.0, 0.0] {
                "−y".to_string()
            } else {
                format!("({:.3}, {:.3}, {:.3})", d[0], d[1], d[2])
            };
            // Along a planar model's hinge axis the hinges hold the load, not the structure.
            if m.out_of_plane == Some(1.0) && m.lambda.is_none() {
                s += &format!(
                    "  d = {dir}: not answered: along the hinges' common axis, which the hinges of \
                     a planar model carry bilaterally (out-of-plane overturning or sliding is \
                     outside the model)\n"
                );
                continue;
            }
            let friction = match (m.required_friction, m.friction_unbounded) {
                (_, true) => " (needs μ > 1000)".to_string(),
                (Some(mu), false) => format!(" (μ ≥ {mu:.4})"),
                (None, false) => String::new(),
            };
            match m.lambda {
                Some(l) => {
                    let joints: Vec<String> =
                        m.opening.iter().map(|(k, v)| format!("{k} {v}")).collect();
                    // A mechanism of lift-offs alone opens no CRR angle (the lines below say).
                    let opening = if joints.is_empty() {
                        String::new()
                    } else {
                        format!(" opening {}", joints.join(", "))
                    };
                    s += &format!("  d = {dir}: λ = {l:.6}{friction}{opening}\n");
                    let with = |motion: crr_impact::statics::Motion| -> Vec<&str> {
                        m.mechanism
                            .iter()
                            .filter(|j| j.motion == motion)
                            .map(|j| j.interface.as_str())
                            .collect()
                    };
                    let lifting = with(crr_impact::statics::Motion::LiftsOff);
                    if !lifting.is_empty() {
                        s += &format!(
                            "    lifting off: {} (a block leaves a support: `crr simulate` takes these faces out of the dynamic chain until they land)\n",
                            lifting.join(", ")
                        );
                    }
                    s += &sliding_note(m, r.exhaustive_sets);
                    let sliding = with(crr_impact::statics::Motion::Slides);
                    if !sliding.is_empty() {
                        s += &format!(
                            "    sliding: {} (outside the CRR chain, which allows no sliding)\n",
                            sliding.join(", ")
                        );
                    }
                }
                None => {
                    s += &format!(
                        "  d = {dir}: holds up to λ = {}{friction}\n",
                        crate::analysis::static_multiplier::LAMBDA_MAX
                    );
                    s += &sliding_note(m, r.exhaustive_sets);
                }
            }
            if !m.hinges_out_of_plane.is_empty() {
                s += &format!(
                    "    relies on hinges carrying loads out of their plane: {} (every distribution \
                     at λ loads them so; a hinge is a line, which transmits couples out of its \
                     plane and forces along its axis whatever they are, with no out-of-plane \
                     geometry to limit them: model those joints as rocking bases)\n",
                    m.hinges_out_of_plane.join(", ")
                );
            }
            if let Some(part) = m.out_of_plane.filter(|&p| p > 0.0) {
                // The load's part in the plane of motion, |d − (d·a)a| = √(1 − (d·a)²).
                let in_plane = (1.0 - part * part).max(0.0).sqrt();
                let answer = match m.lambda {
                    Some(l) => format!(
                        "the in-plane multiplier is λ·{in_plane:.4} = {:.6}",
                        l * in_plane
                    ),
                    None => format!(
                        "the in-plane part holds up to λ·{in_plane:.4} = {:.4}",
                        crate::analysis::static_multiplier::LAMBDA_MAX * in_plane
                    ),
                };
                s += &format!(
                    "    d is {:.1}° out of the plane of motion (|d·a| = {part:.4}, a the hinges' \
                     common axis, which they carry bilaterally): only its in-plane part is \
                     answered; {answer}\n",
                    part.asin().to_degrees()
                );
            }
        }
    }
    if r.static_multipliers.iter().any(|m| m.friction_unbounded) {
        // Such an answer stands on shear across a joint whose compression vanishes: no friction
        // gives it, and a rounding of the geometry moves it (an arch turned 30° and written
        // with six decimals: 0.435159 for the exact geometry's 0.423857, both 0.423857 at 0.7).
        s += "  an answer that needs μ > 1000 rests on shear across a joint that carries no \
              compression, which no masonry joint gives, and may change with small changes of \
              the geometry: `--friction MU` (a masonry μ, e.g. 0.6 to 0.8) gives the multipliers \
              with Coulomb friction at every contact (docs/check.md)\n";
    }
    if let Some(note) = &r.static_multipliers_note {
        s += &format!("static multiplier: {note}\n");
    }
    if let Some(k) = &r.mechanism {
        s += &format!(
            "\none-DOF mechanism, coordinate {} {} 0 opening on pivots:",
            k.coordinate,
            if k.side == "-" { "<" } else { ">" }
        );
        for (name, code) in &k.pivots {
            s += &format!(" {name} {code}");
        }
        s += "\n";
        if k.alpha_eq < -1e-9 {
            // Its weight opens it: nothing holds it at rest, nothing to activate, and no rocking
            // about a seat to give frequencies for.
            s += &format!(
                "the mechanism falls under its own weight (U′(0) = {:.6e} N m < 0 as it opens, α_eq = {:.6} rad): it has no activation multiplier, equivalent block or free-rocking frequencies (the static multiplier above says what load would hold it)\n",
                k.potential_slope, k.alpha_eq
            );
            return s;
        }
        s += &format!(
            "activation multiplier λ = {:.6} (ground acceleration {:.4} m/s² along {}({:.3}, {:.3}, {:.3}))\n",
            k.lambda,
            k.lambda * r.gravity,
            if k.lambda_sign < 0.0 { "−" } else { "+" },
            k.direction[0],
            k.direction[1],
            k.direction[2]
        );
        s += &format!(
            "equivalent block: M(0) = {:.6e} kg m², U′(0) = {:.6e} N m, U″(0) = {:.6e} N m\n",
            k.mass, k.potential_slope, k.potential_curvature
        );
        s += &format!(
            "  α_eq = {:.6} rad, p_eq = {:.6} rad/s (p_eq² = {:.6} 1/s², linearised {:.6})\n",
            k.alpha_eq, k.p_eq, k.p_squared, k.p_squared_linearised
        );
        s += &format!(
            "  r (momentum law) = {:.6}, T⁺/T⁻ = {:.6}, mode change {:.1e}\n",
            k.r, k.energy_ratio, k.mode_change
        );
        if seats_at_impact(k.r, k.mode_change) {
            s += "  r < 0: the law would turn the mechanism on into its seat, so its first impact seats it and the rocking ends there (T⁺ = 0)\n";
        }
        let l = &k.lagrangian;
        s += "one-DOF Lagrangian (eq 4): L/M(0) = ½(1 ± νθ + ξθ²)θ̇² ∓ ηθ + ½χθ² (NOTATION.md)\n";
        s += &format!(
            "  ν = {:.6e} 1/rad, ξ = {:.6e} 1/rad², η = {:.6} 1/s², χ = {:.6} 1/s²\n",
            l.nu, l.xi, l.eta, l.chi
        );
        s += &format!(
            "  eq 6: χ = p_eq² = {:.6} 1/s², ε = 1/α_eq = {:.6} 1/rad\n",
            l.chi_housner, l.epsilon
        );
        s += "\nfree-rocking frequency versus amplitude\n";
        s += "θm/α    θm (rad)   F_H Housner (Hz)   engine (Hz)   engine/F_H\n";
        for f in &k.frequencies {
            let (e, q) = match (f.engine_hz, f.ratio) {
                (Some(e), Some(q)) => (format!("{e:.6}"), format!("{q:.5}")),
                _ => ("–".to_string(), "–".to_string()),
            };
            s += &format!(
                "{:<6.1} {:<10.6} {:<18.6} {:<13} {}\n",
                f.amplitude_ratio, f.theta_m, f.housner_hz, e, q
            );
        }
    }
    s
}

/// Whether the momentum law's impact seats the one-DOF mechanism: r < 0 (a squat block,
/// sin²α > 2/3 for Housner's) with the velocity after it a multiple of the one before (mode
/// change below 1e-9): every joint's rate after it would turn into its seat, so the impact seats
/// the mechanism and the rocking ends there, as `crr simulate` does. Where the mode changes,
/// other joints may keep rocking, and T⁺/T⁻ is the law's.
pub fn seats_at_impact(r: f64, mode_change: f64) -> bool {
    r < 0.0 && mode_change <= 1e-9
}
