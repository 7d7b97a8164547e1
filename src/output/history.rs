//! The tables of a run: `history.csv` (one row per sample) and `impacts.csv` (one row per
//! impact), documented in `docs/outputs.md`.

use crr_impact::simulation::{Sample, Trajectory};
use crr_kinematics::Model;

fn num(x: f64) -> String {
    format!("{x:e}")
}

/// The header line of `history.csv`.
pub fn history_header(model: &Model) -> String {
    let mut s = String::from("t");
    for c in &model.coords {
        s.push(',');
        s.push_str(&c.name);
    }
    for c in &model.coords {
        s.push_str(&format!(",{}_rate", c.name));
    }
    s.push_str(",kinetic,potential,work_in,dissipated");
    for i in &model.interfaces {
        s.push_str(&format!(",{}_state", i.name));
    }
    s.push('\n');
    s
}

/// One line of `history.csv`.
pub fn history_row(model: &Model, x: &Sample) -> String {
    let mut s = String::with_capacity(24 * (2 * x.q.len() + 5) + 8 * model.interfaces.len());
    push_history_row(&mut s, model, x);
    s
}

/// Appends one line of `history.csv` to `s`, formatting in place (no string per value: writing
/// the history was a quarter of a short run's time).
pub fn push_history_row(s: &mut String, model: &Model, x: &Sample<'_>) {
    use std::fmt::Write;
    // Writing to a String cannot fail.
    let _ = write!(s, "{:e}", x.t);
    for v in x.q.iter().chain(x.qdot.iter()) {
        let _ = write!(s, ",{v:e}");
    }
    for v in [x.kinetic, x.potential, x.work_in, x.dissipated] {
        let _ = write!(s, ",{v:e}");
    }
    for i in &model.interfaces {
        s.push(',');
        for (k, slot) in i.slots.clone().enumerate() {
            if k > 0 {
                s.push('/');
            }
            s.push_str(x.states.get(slot).map_or("?", |st| st.code()));
        }
    }
    s.push('\n');
}

/// The header line of `openings.csv`: one row per face open at a sample of `history.csv`
/// (`row`, 1 = its first data row), with the face's offset x_c(P⁺) − x_p(P⁺) in world axes (m,
/// [`crr_impact::simulation::FaceOpening`]).
pub const OPENINGS_HEADER: &str = "row,t,interface,dx,dy,dz\n";

/// Appends the rows of `openings.csv` for sample `x`, row `row` of `history.csv` (1 = the first
/// data row): one per face open at it, none when no face is.
pub fn push_openings_rows(s: &mut String, model: &Model, row: usize, x: &Sample<'_>) {
    use std::fmt::Write;
    for o in x.openings {
        let name = &model.interfaces[o.interface].name;
        let [dx, dy, dz] = o.offset;
        // Writing to a String cannot fail.
        let _ = writeln!(s, "{row},{:e},{name},{dx:e},{dy:e},{dz:e}", x.t);
    }
}

/// The text of `openings.csv` for the samples a trajectory holds.
pub fn openings_csv(model: &Model, t: &Trajectory) -> String {
    let mut s = String::from(OPENINGS_HEADER);
    for (i, x) in t.samples.iter().enumerate() {
        push_openings_rows(&mut s, model, i + 1, &x);
    }
    s
}

/// The text of `history.csv` for the samples a trajectory holds.
pub fn history_csv(model: &Model, t: &Trajectory) -> String {
    let mut s = history_header(model);
    for x in &t.samples {
        push_history_row(&mut s, model, &x);
    }
    s
}

/// The text of `impacts.csv`: one row per impact, with the seated joints it opened (slot names,
/// as `crr inspect` names them) last.
pub fn impacts_csv(model: &Model, t: &Trajectory) -> String {
    let mut s = String::from("t,interfaces,rates_before,rates_after,energy_lost,opened\n");
    let join = |v: &[f64]| v.iter().map(|x| num(*x)).collect::<Vec<_>>().join(";");
    for i in &t.impacts {
        s.push_str(&format!(
            "{},{},{},{},{},{}\n",
            num(i.t),
            i.interfaces.join(";"),
            join(&i.rates_before),
            join(&i.rates_after),
            num(i.energy_lost),
            opened_names(model, &i.released).join(";")
        ));
    }
    s
}

/// The text of `hops.csv`: one row per pull at a pivot where a segment started (just after an
/// impact), measured by the motion with that face released (docs/simulation.md, "Hops"), in
/// the order they ended; `within_tolerance` against the run's `hop_tolerance`.
pub fn hops_csv(t: &Trajectory, tolerance: f64) -> String {
    let mut s = String::from(
        "interface,start,pull_end,end,largest_pull,separation,departure,closed,opens,\
         within_tolerance\n",
    );
    for h in &t.hops {
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{}\n",
            h.interface,
            num(h.start),
            h.pull_end.map(num).unwrap_or_default(),
            num(h.end),
            num(h.largest_pull),
            num(h.separation),
            num(h.departure),
            h.closed,
            h.opens,
            h.within(tolerance)
        ));
    }
    s
}

/// The names of the seated joints an impact opened (`ImpactRecord::released`), by slot.
pub fn opened_names(model: &Model, released: &[usize]) -> Vec<String> {
    released.iter().map(|&k| model.slot_name(k)).collect()
}
