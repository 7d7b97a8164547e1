//! Angle slots: their angles and rates, the interface each belongs to, and the initial states
//! a simulation accepts.

use super::*;

/// Checks that an initial state can be simulated: finite, and no rocking joint turned beyond
/// ±π/2 (its body would be through its support). The message names the joint.
pub fn check_initial_state(model: &Model, initial: &InitialState) -> Result<(), String> {
    let mut kin = Data::new(model);
    let mut angles = vec![0.0; model.slot_count];
    slot_angles(model, &mut kin, &initial.q, &initial.pivots, &mut angles);
    crr_kinematics::velocities(model, &mut kin, &initial.qdot);
    let mut rates = vec![0.0; model.slot_count];
    slot_rates(model, &kin, &initial.qdot, &mut rates);
    for s in 0..model.slot_count {
        let iface = &model.interfaces[slot_interface(model, s)];
        if !(angles[s].is_finite() && rates[s].is_finite()) {
            return Err(format!(
                "the initial state of {} is not finite (angle {:e} rad, rate {:e} rad/s)",
                iface.name, angles[s], rates[s]
            ));
        }
        if is_contact(&iface.kind) && angles[s].abs() >= 0.5 * std::f64::consts::PI {
            return Err(format!(
                "the initial angle of {} is {:e} rad: a rocking joint turned beyond ±π/2 puts \
                 its body through its support",
                iface.name, angles[s]
            ));
        }
    }
    Ok(())
}

/// Per slot of `model`, whether its interface is a rocking contact ([`is_contact`]).
pub(super) fn contact_slots(model: &Model) -> Vec<bool> {
    (0..model.slot_count)
        .map(|s| is_contact(&model.interfaces[slot_interface(model, s)].kind))
        .collect()
}

/// A joint with two distinct pivots (a rocking contact), as opposed to a plain hinge.
pub(super) fn is_contact(kind: &InterfaceKind) -> bool {
    match kind {
        InterfaceKind::Hinge {
            axis,
            pivot_positive,
            pivot_negative,
        } => (pivot_positive - pivot_negative).cross(axis).norm() > 0.0,
        InterfaceKind::RockingBase { .. } => true,
    }
}

/// Angle of every slot at q (tree coordinates, then closure angles). Fills `kin`.
pub(super) fn slot_angles(
    model: &Model,
    kin: &mut Data,
    q: &DVector<f64>,
    pivots: &ActivePivots,
    out: &mut [f64],
) {
    let n = model.dof();
    out[..n].copy_from_slice(q.as_slice());
    forward_kinematics(model, kin, q, pivots);
    closure_angles(model, kin, &mut out[n..]);
}

/// Rate ψ̇ = aᵀq̇ of every slot. Needs kinematics and velocities in `kin`.
pub(super) fn slot_rates(model: &Model, kin: &Data, qdot: &DVector<f64>, out: &mut [f64]) {
    let n = model.dof();
    let mut row = DVector::zeros(if out.len() > n { n } else { 0 });
    for (s, o) in out.iter_mut().enumerate() {
        if s < n {
            // A tree slot's row is eₛ: its rate is q̇ₛ (0 + q̇ₛ, the +0 of eₛᵀq̇ when q̇ₛ = −0).
            *o = 0.0 + qdot[s];
        } else {
            slot_row(model, kin, s, &mut row);
            *o = row.dot(qdot);
        }
    }
}

pub(crate) fn slot_interface(model: &Model, slot: usize) -> usize {
    model
        .interfaces
        .iter()
        .position(|i| i.slots.contains(&slot))
        .expect("every slot belongs to an interface")
}
