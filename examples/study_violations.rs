//! What the cases of a study that leave crr's model break, and how much: every case is run as
//! `crr study` runs it, and its first hypotheses violation is set against the run's impacts.
//! For a `tension` (a face that would pull, the bodies it carries flying) it prints |N|, the
//! time to the next impact Δt and the lift ½ |N|/m Δt² the pull would give the bodies the face
//! carries (mass m) if it held its first value until then, and the pull measured as a hop
//! (docs/simulation.md, "Hops": whether the face released opens, lands again, and how far the
//! bodies depart from crr's motion meanwhile). The numbers of docs/studies.md, "Cases that leave
//! the model", come from
//!
//! ```sh
//! cargo run --release --example study_violations -- examples/studies/drum_fragility.toml
//! ```
//!
//! (open chains only: the bodies a face carries are those above it in the tree).

use std::path::Path;

use rayon::prelude::*;

use crr::analysis::simulation::simulate;
use crr::analysis::study::Study;
use crr::kinematics::Model;

/// The mass (kg) of the bodies interface `i` carries: those whose path to the ground in the
/// tree passes through one of its coordinates.
fn carried_mass(model: &Model, i: usize) -> f64 {
    let mut mass = 0.0;
    for (b, body) in model.bodies.iter().enumerate() {
        let mut k = Some(model.body_coord[b]);
        while let Some(c) = k {
            if model.coords[c].interface == i {
                mass += body.mass;
                break;
            }
            k = model.coords[c].parent;
        }
    }
    mass
}

/// One case's violation: (case id, kind, at an impact's instant, |N| in N, Δt to the next
/// impact in s, lift in m, its hop).
type Row = (
    String,
    String,
    bool,
    f64,
    Option<f64>,
    Option<f64>,
    Option<crr::impact::simulation::Hop>,
);

fn main() {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "examples/studies/drum_fragility.toml".into());
    let study = Study::load(Path::new(&path)).unwrap_or_else(|e| panic!("{path}: {e}"));
    let rows: Vec<Row> = study
        .cases
        .par_iter()
        .filter_map(|case| {
            let ground = study.ground_motion(case).ok()?;
            let mut params = study.params.clone();
            params.duration = study.duration(&ground);
            let v = &study.variants[case.variant];
            let mut drop_samples = |_: &crr::impact::Samples| Ok(());
            let (t, _) = simulate(
                &v.model,
                &ground,
                &v.initial,
                &params,
                &mut drop_samples,
                true,
                false,
                None,
                None,
            )
            .ok()?;
            let viol = t.violation?;
            let at_impact = t.impacts.iter().any(|i| i.t == viol.t);
            let gap = t
                .impacts
                .iter()
                .find(|i| i.t > viol.t)
                .map(|i| i.t - viol.t);
            let interface = v
                .model
                .interfaces
                .iter()
                .position(|i| i.name == viol.interface)?;
            let m = carried_mass(&v.model, interface);
            let lift = (viol.kind == "tension" && m > 0.0)
                .then(|| gap.map(|dt| 0.5 * viol.normal.abs() / m * dt * dt))
                .flatten();
            Some((
                case.id.clone(),
                viol.kind,
                at_impact,
                viol.normal.abs(),
                gap,
                lift,
                viol.hop.as_deref().cloned(),
            ))
        })
        .collect();
    for (id, kind, at_impact, n, gap, lift, hop) in &rows {
        let hop = hop.as_ref().map(|h| {
            format!(
                "opens={} landed={} separation={:.2e} m departure={:.2e} m",
                h.opens, h.closed, h.separation, h.departure
            )
        });
        println!(
            "{id} {kind} at_impact={at_impact} |N|={n:.1} N next_impact={gap:?} s lift={lift:?} m \
             hop: {}",
            hop.unwrap_or_default()
        );
    }
    let hops: Vec<&crr::impact::simulation::Hop> =
        rows.iter().filter_map(|r| r.6.as_ref()).collect();
    let mut departures: Vec<f64> = hops
        .iter()
        .filter(|h| h.opens && h.closed)
        .map(|h| h.departure)
        .collect();
    departures.sort_by(f64::total_cmp);
    let at = |q: f64| {
        departures
            .get(((departures.len() as f64 - 1.0) * q).round() as usize)
            .copied()
            .unwrap_or(f64::NAN)
    };
    println!(
        "hops: {} of the violations; {} do not open, {} not shown to land; the {} that \
         land depart from crr's motion by {:.2e} m (least), {:.2e} (median), {:.2e} (90 %), \
         {:.2e} m (largest)",
        hops.len(),
        hops.iter().filter(|h| !h.opens).count(),
        hops.iter().filter(|h| h.opens && !h.closed).count(),
        departures.len(),
        at(0.0),
        at(0.5),
        at(0.9),
        at(1.0)
    );
    let weight = study.model.total_mass() * study.model.gravity;
    let forces: Vec<f64> = rows.iter().map(|r| r.3).collect();
    let mut gaps: Vec<f64> = rows.iter().filter_map(|r| r.4).collect();
    gaps.sort_by(f64::total_cmp);
    let lift = rows.iter().filter_map(|r| r.5).fold(0.0f64, f64::max);
    let (lo, hi) = (
        forces.iter().copied().fold(f64::INFINITY, f64::min),
        forces.iter().copied().fold(0.0f64, f64::max),
    );
    println!(
        "{} of {} cases leave the model; {} at an impact's instant; |N| {lo:.0} to {hi:.0} N \
         ({:.2} to {:.2} % of the weight {weight:.0} N); next impact {:.2e} to {:.2e} s \
         (median {:.2e} s); largest lift {lift:.2e} m",
        rows.len(),
        study.cases.len(),
        rows.iter().filter(|r| r.2).count(),
        100.0 * lo / weight,
        100.0 * hi / weight,
        gaps.first().copied().unwrap_or(f64::NAN),
        gaps.last().copied().unwrap_or(f64::NAN),
        gaps.get(gaps.len() / 2).copied().unwrap_or(f64::NAN),
    );
}
