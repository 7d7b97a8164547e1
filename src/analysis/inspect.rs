//! `crr inspect`: the model's coordinates, mass properties and kinematic quantities at one
//! configuration, as text or JSON (keys documented in `docs/inspect.md`).

use nalgebra::{DMatrix, DVector, Vector3};
use serde::Serialize;

use crr_kinematics::{
    ActivePivots, Data, InterfaceKind, Model, Side, closure_angles, constraint_jacobian,
    constraint_residual, forward_kinematics, generalized_gravity, kinematics::body_rotation,
    mass_matrix, potential_energy,
};

use crate::Error;

/// One generalized coordinate.
#[derive(Debug, Serialize)]
pub struct CoordinateReport {
    /// Position in q (0-based).
    pub index: usize,
    /// Name (`<interface>` or `<interface>.1` / `.2`).
    pub name: String,
    /// Interface it belongs to.
    pub interface: String,
    /// Unit axis at rest (world).
    pub axis: [f64; 3],
    /// Its value in this configuration (rad).
    pub value: f64,
    /// Active pivot side, "+" or "-".
    pub pivot: String,
}

/// One loop closure.
#[derive(Debug, Serialize)]
pub struct ClosureReport {
    /// Interface name.
    pub interface: String,
    /// Kind: "hinge" or "rocking_base".
    pub kind: String,
    /// Rows of Φ it contributes.
    pub rows: usize,
    /// Its relative angle(s) in this configuration (rad).
    pub angles: Vec<f64>,
}

/// One body.
#[derive(Debug, Serialize)]
pub struct BodyReport {
    /// Name.
    pub name: String,
    /// Shape kind.
    pub shape: String,
    /// Mass (kg).
    pub mass: f64,
    /// Volume (m³).
    pub volume: f64,
    /// Density (kg/m³).
    pub density: f64,
    /// Centre of mass at rest (m).
    pub center_at_rest: [f64; 3],
    /// Inertia tensor about the centre, world axes at rest (kg m²), row-major 3×3.
    pub inertia: [[f64; 3]; 3],
    /// Centre of mass in this configuration (m).
    pub center: [f64; 3],
    /// Rotation from rest Γ (row-major 3×3).
    pub rotation: [[f64; 3]; 3],
}

/// Everything `crr inspect` reports.
#[derive(Debug, Serialize)]
pub struct InspectReport {
    /// Model name.
    pub model: String,
    /// g used (m/s²).
    pub gravity: f64,
    /// DOF(1): number of tree coordinates.
    pub dof: usize,
    /// Coordinates in the order of q.
    pub coordinates: Vec<CoordinateReport>,
    /// Loop closures.
    pub closures: Vec<ClosureReport>,
    /// Bodies.
    pub bodies: Vec<BodyReport>,
    /// M(q) (kg m²), row-major.
    pub mass_matrix: Vec<Vec<f64>>,
    /// −∂U/∂q (N m).
    pub generalized_gravity: Vec<f64>,
    /// U = Σ m g z of the centres, absolute (J).
    pub potential_energy: f64,
    /// Φ(q) when there are closures.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub constraint_residual: Option<Vec<f64>>,
    /// Φ_q when there are closures (row-major).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub constraint_jacobian: Option<Vec<Vec<f64>>>,
}

fn rows(m: &DMatrix<f64>) -> Vec<Vec<f64>> {
    m.row_iter().map(|r| r.iter().copied().collect()).collect()
}

fn mat3(m: &nalgebra::Matrix3<f64>) -> [[f64; 3]; 3] {
    [
        [m[(0, 0)], m[(0, 1)], m[(0, 2)]],
        [m[(1, 0)], m[(1, 1)], m[(1, 2)]],
        [m[(2, 0)], m[(2, 1)], m[(2, 2)]],
    ]
}

/// Parses `NAME=VALUE` settings of coordinates (rad) into q; other coordinates are 0.
pub fn configuration(model: &Model, settings: &[String]) -> Result<DVector<f64>, Error> {
    let mut q = DVector::zeros(model.dof());
    let mut given = vec![false; model.dof()];
    for s in settings {
        let (name, value) = s
            .split_once('=')
            .ok_or_else(|| Error::Argument(format!("--q {s}: expected NAME=VALUE (radians)")))?;
        let k = model.coord_index(name.trim()).ok_or_else(|| {
            let names: Vec<_> = model.coords.iter().map(|c| c.name.as_str()).collect();
            Error::Argument(format!(
                "--q {s}: no coordinate named \"{}\"; coordinates are: {}",
                name.trim(),
                names.join(", ")
            ))
        })?;
        let v: f64 = value
            .trim()
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| {
                Error::Argument(format!(
                    "--q {s}: \"{}\" is not a finite number of radians",
                    value.trim()
                ))
            })?;
        if std::mem::replace(&mut given[k], true) {
            return Err(Error::Argument(format!(
                "--q {s}: the coordinate \"{}\" is given twice",
                name.trim()
            )));
        }
        q[k] = v;
    }
    Ok(q)
}

/// Evaluates the report for configuration q. Active pivots follow the signs of q (P⁺ at 0);
/// closure pivots follow the signs of the closure angles.
pub fn inspect(model: &Model, q: &DVector<f64>) -> InspectReport {
    let mut data = Data::new(model);
    let mut pivots = ActivePivots::uniform(model, Side::Positive);
    pivots.follow_coordinates(q);
    forward_kinematics(model, &mut data, q, &pivots);
    let n_closure_slots = model.slot_count - model.dof();
    let mut cl_angles = vec![0.0; n_closure_slots];
    closure_angles(model, &data, &mut cl_angles);
    for (k, a) in cl_angles.iter().enumerate() {
        let s = &mut pivots.sides[model.dof() + k];
        *s = Side::of(*a, *s);
    }
    forward_kinematics(model, &mut data, q, &pivots);
    // M(q) and Q(q) sum spatial quantities about the origin: a model far from it has them
    // computed moved near it, where they are the same up to the round-off the move avoids.
    let moved = model.moved_near_origin();
    let (dynamic, mut moved_data) = match &moved {
        Some(m) => {
            let mut d = Data::new(m);
            forward_kinematics(m, &mut d, q, &pivots);
            (m, Some(d))
        }
        None => (model, None),
    };
    let dynamic_data = moved_data.as_mut().unwrap_or(&mut data);
    mass_matrix(dynamic, dynamic_data);
    let mut qg = DVector::zeros(model.dof());
    generalized_gravity(
        dynamic,
        dynamic_data,
        &Vector3::new(0.0, 0.0, -model.gravity),
        &mut qg,
    );
    let mass_matrix_rows = rows(&dynamic_data.mass_matrix);
    let has_closures = model.constraint_rows > 0;
    if has_closures {
        constraint_residual(model, &mut data, &pivots, q);
        constraint_jacobian(model, &mut data, &pivots);
    }
    InspectReport {
        model: model.name.clone(),
        gravity: model.gravity,
        dof: model.dof(),
        coordinates: model
            .coords
            .iter()
            .enumerate()
            .map(|(k, c)| CoordinateReport {
                index: k,
                name: c.name.clone(),
                interface: model.interfaces[c.interface].name.clone(),
                axis: c.axis.into(),
                value: q[k],
                pivot: if pivots.sides[k] == Side::Positive {
                    "+"
                } else {
                    "-"
                }
                .into(),
            })
            .collect(),
        closures: model
            .closures
            .iter()
            .map(|cl| {
                let iface = &model.interfaces[cl.interface];
                let slots = iface.slots.start - model.dof()..iface.slots.end - model.dof();
                ClosureReport {
                    interface: iface.name.clone(),
                    kind: match iface.kind {
                        InterfaceKind::Hinge { .. } => "hinge",
                        InterfaceKind::RockingBase { .. } => "rocking_base",
                    }
                    .into(),
                    rows: cl.rows,
                    angles: cl_angles[slots].to_vec(),
                }
            })
            .collect(),
        bodies: model
            .bodies
            .iter()
            .enumerate()
            .map(|(b, body)| BodyReport {
                name: body.name.clone(),
                shape: body.shape.kind().into(),
                mass: body.mass,
                volume: body.volume,
                density: body.density,
                center_at_rest: body.com.into(),
                inertia: mat3(&body.inertia),
                center: data.com[b].into(),
                rotation: mat3(&body_rotation(model, &data, b)),
            })
            .collect(),
        mass_matrix: mass_matrix_rows,
        generalized_gravity: qg.iter().copied().collect(),
        potential_energy: potential_energy(model, &data),
        constraint_residual: has_closures.then(|| data.phi.iter().copied().collect()),
        constraint_jacobian: has_closures.then(|| rows(&data.phi_q)),
    }
}

fn fmt_row(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x:>14.6e}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Human-readable text of a report.
pub fn to_text(r: &InspectReport) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(s, "model {:?}   g = {} m/s²", r.model, r.gravity);
    let _ = writeln!(
        s,
        "DOF(1) = {} coordinate(s), {} loop closure(s)",
        r.dof,
        r.closures.len()
    );
    let _ = writeln!(s, "\ncoordinates (order of q):");
    for c in &r.coordinates {
        let _ = writeln!(
            s,
            "  q[{}] {:<16} = {:>10.6} rad  pivot {}  axis [{:.4}, {:.4}, {:.4}]  (interface {})",
            c.index, c.name, c.value, c.pivot, c.axis[0], c.axis[1], c.axis[2], c.interface
        );
    }
    if !r.closures.is_empty() {
        let _ = writeln!(s, "\nloop closures:");
        for c in &r.closures {
            let _ = writeln!(
                s,
                "  {:<16} {} ({} rows of Φ), angle(s) {:?}",
                c.interface, c.kind, c.rows, c.angles
            );
        }
    }
    let _ = writeln!(s, "\nbodies:");
    for b in &r.bodies {
        let _ = writeln!(
            s,
            "  {} ({}): mass {:.6} kg, volume {:.6} m³, density {:.3} kg/m³",
            b.name, b.shape, b.mass, b.volume, b.density
        );
        let _ = writeln!(
            s,
            "    centre at rest [{:.6}, {:.6}, {:.6}] m",
            b.center_at_rest[0], b.center_at_rest[1], b.center_at_rest[2]
        );
        let _ = writeln!(s, "    inertia about centre (kg m²):");
        for row in &b.inertia {
            let _ = writeln!(s, "      {}", fmt_row(row));
        }
        let _ = writeln!(
            s,
            "    centre now [{:.6}, {:.6}, {:.6}] m",
            b.center[0], b.center[1], b.center[2]
        );
        let _ = writeln!(s, "    rotation Γ:");
        for row in &b.rotation {
            let _ = writeln!(s, "      {}", fmt_row(row));
        }
    }
    let _ = writeln!(s, "\nmass matrix M(q) (kg m²):");
    for row in &r.mass_matrix {
        let _ = writeln!(s, "  {}", fmt_row(row));
    }
    let _ = writeln!(
        s,
        "\ngeneralized gravity −∂U/∂q (N m):\n  {}",
        fmt_row(&r.generalized_gravity)
    );
    let _ = writeln!(
        s,
        "\npotential energy U = Σ m g z = {:.9e} J",
        r.potential_energy
    );
    if let (Some(phi), Some(jac)) = (&r.constraint_residual, &r.constraint_jacobian) {
        let _ = writeln!(s, "\nconstraint residual Φ(q):\n  {}", fmt_row(phi));
        let _ = writeln!(s, "constraint Jacobian Φ_q:");
        for row in jac {
            let _ = writeln!(s, "  {}", fmt_row(row));
        }
    }
    s
}
