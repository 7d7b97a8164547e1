//! Energy levels of any one-DOF mechanism (the paper's Fig. 6 generalised): the phase portrait of
//! the mechanism coordinate θ with the curves E(θ, θ̇) = U(θ) + ½ M(θ) θ̇² = const, where U and M are
//! the engine's own potential and reduced mass *along the mechanism*, not a block formula.
//!
//! For each side of rest (θ > 0 and θ < 0) the pivots are those of the opening state, found as
//! `crr check` finds them (`solve_initial` at θ = ±0.01 rad). From θ = 0 the mechanism is followed
//! in steps of θ: the closure solve (`mechanism::configuration`, Newton from the previous
//! configuration) gives the full q(θ), `mechanism::reduce_at` the velocity map B = dq/dθ, the
//! reduced mass M(θ) = Bᵀ M(q) B and the slope U′(θ) = −Bᵀ Q_gravity; U(θ) = U(q(θ)) − U(rest) is the
//! engine's potential energy (eq 3). A side ends at the overturning angle, where U′ changes sign
//! (refined by bisection on U′), or where the mechanism locks: the closure solve or the reduction
//! fails, or a hinge of the chain closes back through 0 (its pivot would switch), or at
//! [`THETA_LIMIT`].

use std::collections::BTreeMap;
use std::fmt::Write as _;

use nalgebra::{DVector, Vector3};
use serde::Serialize;

use crr_dynamics::mechanism::{configuration, reduce_at};
use crr_dynamics::{InitialSpec, solve_initial};
use crr_kinematics::{
    ActivePivots, Data, Model, Side, closure_angles, forward_kinematics, potential_energy,
};

/// Largest |θ| (rad) followed on either side.
pub const THETA_LIMIT: f64 = std::f64::consts::FRAC_PI_2;

/// Default step of θ (rad) between samples.
pub const DEFAULT_STEP: f64 = 1e-3;

/// Fewest steps on a side: a side reached in fewer steps of the given size is followed again with
/// its reach divided by this.
pub const MIN_STEPS: usize = 100;

/// Amplitude fractions of the overturning angle on the θ > 0 side that set the drawn levels
/// (θm/θ_over = 0.25, 0.5, 0.75, as the single block's θm/α of `crr plot`); the separatrix is
/// added to them.
pub const LEVEL_FRACTIONS: [f64; 3] = [0.25, 0.5, 0.75];

/// One point of the mechanism.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LevelSample {
    /// θ (rad).
    pub theta: f64,
    /// U(θ) − U(rest) (J).
    pub potential: f64,
    /// dU/dθ = −Bᵀ Q_gravity (N m).
    pub slope: f64,
    /// M(θ) = Bᵀ M(q) B (kg m²).
    pub mass: f64,
}

/// How a side of the mechanism ends.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SideEnd {
    /// U has its maximum here: beyond it the mechanism overturns.
    Overturning,
    /// The mechanism locks or changes (the reason).
    Locked(String),
    /// [`THETA_LIMIT`] was reached with U still rising.
    Limit,
}

/// The mechanism followed from rest to one side.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SideLevels {
    /// +1 for θ > 0, −1 for θ < 0.
    pub sign: f64,
    /// Pivot side of every slot on this side (`+`/`-`), by interface (joined by `/`).
    pub pivots: BTreeMap<String, String>,
    /// Samples from θ = 0 outwards (|θ| increasing); the last one is the end.
    pub samples: Vec<LevelSample>,
    /// How it ends.
    pub end: SideEnd,
}

impl SideLevels {
    /// The last sample (the end of this side).
    pub fn last(&self) -> LevelSample {
        *self
            .samples
            .last()
            .expect("a side has at least the rest sample")
    }
}

/// The energy levels of a one-DOF mechanism.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MechanismLevels {
    /// The mechanism coordinate θ (the first coordinate, as in `crr check`).
    pub coordinate: String,
    /// The θ < 0 side.
    pub negative: SideLevels,
    /// The θ > 0 side.
    pub positive: SideLevels,
    /// The separatrix energy (J above rest): the lower of the two overturning energies, `None`
    /// when neither side overturns or a side locks at a lower energy.
    pub separatrix: Option<f64>,
    /// The energies of the drawn levels below the separatrix (J above rest), increasing.
    pub energies: Vec<f64>,
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

/// The unit horizontal direction perpendicular to coordinate `c`'s axis (x when it is vertical).
fn horizontal(model: &Model, c: usize) -> Vector3<f64> {
    crr_dynamics::horizontal_direction(model, c)
}

/// Evaluates the mechanism at θ from the closed configuration `q_prev` (Newton start):
/// the configuration, U − U(rest), U′ and M. Errors say why the mechanism cannot be followed
/// there (closure solve, reduction, or a slot angle whose sign disagrees with its pivot).
pub fn evaluate(
    model: &Model,
    pivots: &ActivePivots,
    coordinate: usize,
    q_prev: &DVector<f64>,
    theta: f64,
    u_rest: f64,
) -> Result<(DVector<f64>, LevelSample), String> {
    let q = configuration(model, q_prev, pivots, coordinate, theta).map_err(|e| e.to_string())?;
    if !q.iter().all(|x| x.is_finite()) {
        return Err("the closure solve gave a non-finite configuration".into());
    }
    let mut kin = Data::new(model);
    forward_kinematics(model, &mut kin, &q, pivots);
    let mut angles: Vec<f64> = q.iter().copied().collect();
    angles.resize(model.slot_count, 0.0);
    closure_angles(model, &kin, &mut angles[model.dof()..]);
    // A slot whose angle has the sign of the other pivot: that hinge closed through 0.
    for iface in &model.interfaces {
        for s in iface.slots.clone() {
            let a = angles[s];
            if a.abs() > 1e-9 && Side::of(a, pivots.sides[s]) != pivots.sides[s] {
                return Err(format!(
                    "interface \"{}\" closes back through 0 at θ = {theta:.6} rad",
                    iface.name
                ));
            }
        }
    }
    let u = potential_energy(model, &kin) - u_rest;
    let d = horizontal(model, coordinate);
    let r = reduce_at(model, &q, pivots, coordinate, &d).map_err(|e| e.to_string())?;
    if !(r.mass.is_finite() && r.potential_slope.is_finite() && u.is_finite()) {
        return Err("non-finite reduced mass or potential".into());
    }
    if r.mass <= 0.0 {
        return Err(format!(
            "the reduced mass M(θ) = {:e} is not positive",
            r.mass
        ));
    }
    Ok((
        q,
        LevelSample {
            theta,
            potential: u,
            slope: r.potential_slope,
            mass: r.mass,
        },
    ))
}

/// The opening pivots of side `sign` (±1) of coordinate `coordinate`, as `crr check` finds them.
pub fn opening_pivots(model: &Model, coordinate: usize, sign: f64) -> Result<ActivePivots, String> {
    let spec = InitialSpec {
        angles: [(
            model.coords[coordinate].name.clone(),
            crr_dynamics::mechanism::SIDE_PROBE_ANGLE * sign,
        )]
        .into_iter()
        .collect(),
        rates: BTreeMap::new(),
    };
    solve_initial(model, &spec)
        .map(|s| s.pivots)
        .map_err(|e| e.to_string())
}

/// The potential energy at rest (q = 0, pivots `+`).
pub fn rest_potential(model: &Model) -> f64 {
    let mut kin = Data::new(model);
    let zero = DVector::zeros(model.dof());
    forward_kinematics(
        model,
        &mut kin,
        &zero,
        &ActivePivots::uniform(model, Side::Positive),
    );
    potential_energy(model, &kin)
}

fn follow_side(
    model: &Model,
    coordinate: usize,
    sign: f64,
    step: f64,
) -> Result<SideLevels, String> {
    let pivots = opening_pivots(model, coordinate, sign)?;
    let u_rest = rest_potential(model);
    let zero = DVector::zeros(model.dof());
    let (mut q, first) = evaluate(model, &pivots, coordinate, &zero, 0.0, u_rest)?;
    if sign * first.slope <= 0.0 {
        return Err(format!(
            "U does not rise from rest for {} {} 0 (U′ = {:.3e} N m): no stable rest, no levels",
            model.coords[coordinate].name,
            if sign > 0.0 { ">" } else { "<" },
            first.slope
        ));
    }
    let mut samples = vec![first];
    let end = loop {
        let prev = *samples.last().expect("non-empty");
        let theta = prev.theta + sign * step;
        if theta.abs() > THETA_LIMIT {
            break SideEnd::Limit;
        }
        let (qn, s) = match evaluate(model, &pivots, coordinate, &q, theta, u_rest) {
            Ok(x) => x,
            Err(e) => break SideEnd::Locked(e),
        };
        if sign * s.slope <= 0.0 {
            // U′ changed sign between prev and s: bisection on U′ for the maximum of U.
            let (mut lo, mut hi) = (prev.theta, theta);
            let mut best = (q.clone(), prev);
            for _ in 0..60 {
                if (hi - lo).abs() <= 1e-13 {
                    break;
                }
                let mid = 0.5 * (lo + hi);
                match evaluate(model, &pivots, coordinate, &best.0, mid, u_rest) {
                    Ok((qm, sm)) if sign * sm.slope > 0.0 => {
                        lo = mid;
                        best = (qm, sm);
                    }
                    Ok(_) => hi = mid,
                    Err(_) => break,
                }
            }
            if best.1.theta != prev.theta {
                samples.push(best.1);
            }
            break SideEnd::Overturning;
        }
        samples.push(s);
        q = qn;
    };
    Ok(SideLevels {
        sign,
        pivots: slot_codes(model, &pivots),
        samples,
        end,
    })
}

/// Follows the mechanism of coordinate 0 on both sides of rest with the given step (rad; finer
/// when a side ends within [`MIN_STEPS`] steps) and sets
/// the energy levels. Errors when the model is not a one-DOF mechanism there, or rest is not a
/// minimum of U.
pub fn mechanism_levels(model: &Model, step: f64) -> Result<MechanismLevels, String> {
    if model.dof() == 0 {
        return Err("the model has no coordinate".into());
    }
    if !(step.is_finite() && step > 0.0) {
        return Err(format!(
            "the step must be a positive number of rad, got {step}"
        ));
    }
    let coordinate = 0;
    // A side shorter than MIN_STEPS steps (a slender mechanism) is followed again with finer steps.
    let side = |sign: f64| -> Result<SideLevels, String> {
        let s = follow_side(model, coordinate, sign, step)?;
        let reach = s.last().theta.abs();
        if s.samples.len() < MIN_STEPS && reach > 0.0 {
            follow_side(model, coordinate, sign, reach / MIN_STEPS as f64)
        } else {
            Ok(s)
        }
    };
    let positive = side(1.0)?;
    let negative = side(-1.0)?;
    let tops: Vec<f64> = [&positive, &negative]
        .iter()
        .filter(|s| s.end == SideEnd::Overturning)
        .map(|s| s.last().potential)
        .collect();
    // Levels: U at fractions of the reach of the side `crr check` reports (reported_side: not the
    // sense the file gives θ), below the lowest end energy of both sides.
    let reported =
        match crr_dynamics::reported_side(model, coordinate, &horizontal(model, coordinate)) {
            Ok((Side::Negative, _, _)) => &negative,
            _ => &positive,
        };
    let ceiling = positive.last().potential.min(negative.last().potential);
    // The separatrix closes only if no side locks below it.
    let separatrix = tops
        .iter()
        .copied()
        .reduce(f64::min)
        .filter(|top| *top <= ceiling);
    let reach = reported.last().theta;
    let energies = LEVEL_FRACTIONS
        .iter()
        .map(|f| potential_at(&reported.samples, f * reach))
        .filter(|e| *e > 0.0 && *e < ceiling * (1.0 - 1e-9))
        .collect();
    Ok(MechanismLevels {
        coordinate: model.coords[coordinate].name.clone(),
        negative,
        positive,
        separatrix,
        energies,
    })
}

/// U at θ by linear interpolation in the samples of one side (|θ| increasing).
fn potential_at(samples: &[LevelSample], theta: f64) -> f64 {
    let i = samples.partition_point(|s| s.theta.abs() < theta.abs());
    if i == 0 {
        return samples[0].potential;
    }
    if i >= samples.len() {
        return samples[samples.len() - 1].potential;
    }
    let (a, b) = (samples[i - 1], samples[i]);
    let t = (theta - a.theta) / (b.theta - a.theta);
    a.potential + t * (b.potential - a.potential)
}

impl MechanismLevels {
    /// Every sample from the θ < 0 end to the θ > 0 end (θ increasing; θ = 0 appears twice, once
    /// with each side's pivots).
    pub fn samples(&self) -> Vec<LevelSample> {
        let mut v: Vec<LevelSample> = self.negative.samples.iter().rev().copied().collect();
        v.extend(self.positive.samples.iter().copied());
        v
    }

    /// The closed curve of energy `e` (J above rest) in the (θ, θ̇) plane: the upper branch
    /// θ̇ = √(2(e − U)/M) from the left turning point to the right one, then the lower branch
    /// back. Turning points are interpolated linearly in U between samples. Empty when e ≤ 0.
    pub fn curve(&self, e: f64) -> Vec<(f64, f64)> {
        if e.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return Vec::new();
        }
        let mut branch = Vec::new();
        for side in [&self.negative, &self.positive] {
            let mut pts = Vec::new();
            let s = &side.samples;
            for i in 0..s.len() {
                if s[i].potential <= e {
                    let rate = (2.0 * (e - s[i].potential) / s[i].mass).max(0.0).sqrt();
                    pts.push((s[i].theta, rate));
                } else {
                    // Crossing between s[i − 1] (inside) and s[i] (outside).
                    let (a, b) = (s[i - 1], s[i]);
                    let t = (e - a.potential) / (b.potential - a.potential);
                    pts.push((a.theta + t * (b.theta - a.theta), 0.0));
                    break;
                }
            }
            if side.sign < 0.0 {
                pts.reverse();
            }
            branch.extend(pts);
        }
        let lower: Vec<(f64, f64)> = branch.iter().rev().map(|&(x, y)| (x, -y)).collect();
        branch.extend(lower);
        branch
    }

    /// The levels to draw: (energy, is separatrix), increasing.
    pub fn drawn(&self) -> Vec<(f64, bool)> {
        let mut v: Vec<(f64, bool)> = self.energies.iter().map(|e| (*e, false)).collect();
        if let Some(e) = self.separatrix {
            v.push((e, true));
        }
        v
    }

    /// `levels.csv`: `side,theta,U,dU_dtheta,M`, θ increasing.
    pub fn to_csv(&self) -> String {
        let mut s = String::from("side,theta,U,dU_dtheta,M\n");
        for side in [&self.negative, &self.positive] {
            let mut rows: Vec<&LevelSample> = side.samples.iter().collect();
            if side.sign < 0.0 {
                rows.reverse();
            }
            let tag = if side.sign < 0.0 { "-" } else { "+" };
            for r in rows {
                let _ = writeln!(
                    s,
                    "{tag},{:.12e},{:.12e},{:.12e},{:.12e}",
                    r.theta, r.potential, r.slope, r.mass
                );
            }
        }
        s
    }

    /// A one-line description of how each side ends.
    pub fn ends_text(&self) -> String {
        let one = |s: &SideLevels| {
            let l = s.last();
            match &s.end {
                SideEnd::Overturning => format!(
                    "overturns at θ = {:.6} rad (U = {:.6e} J)",
                    l.theta, l.potential
                ),
                SideEnd::Locked(why) => format!("stops at θ = {:.6} rad: {why}", l.theta),
                SideEnd::Limit => format!("followed to θ = {:.6} rad", l.theta),
            }
        };
        format!(
            "θ < 0 {}; θ > 0 {}",
            one(&self.negative),
            one(&self.positive)
        )
    }
}
