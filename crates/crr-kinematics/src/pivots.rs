//! The dynamic chain: which pivot of every interface angle is active.

use nalgebra::DVector;

use crate::model::{Model, Side};
use crate::short_copy::copy_short;

/// The active pivot of every angle slot (the paper's "dynamic chain"): slot k < DOF(1) is
/// coordinate k; the slots after them are the angles of the loop closures
/// ([`crate::Interface::slots`]). Part of the state: an angle at exactly 0 keeps its side.
/// The default has no slots: an empty workspace, filled by `clone_from` before it is read.
#[derive(Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct ActivePivots {
    /// One side per slot.
    pub sides: Vec<Side>,
}

// By hand for `clone_from`: the derived one would allocate a new vector, and workspaces copy the
// run's pivots in at every output sample and uplift test.
impl Clone for ActivePivots {
    fn clone(&self) -> Self {
        Self {
            sides: self.sides.clone(),
        }
    }

    fn clone_from(&mut self, source: &Self) {
        if self.sides.len() == source.sides.len() {
            copy_short(&mut self.sides, &source.sides);
        } else {
            self.sides.clone_from(&source.sides);
        }
    }
}

impl ActivePivots {
    /// Every slot on `side`.
    pub fn uniform(model: &Model, side: Side) -> Self {
        Self {
            sides: vec![side; model.slot_count],
        }
    }

    /// Sides from the signs of the coordinates q (ties and closure slots keep `self`'s sides).
    pub fn follow_coordinates(&mut self, q: &DVector<f64>) {
        for (k, s) in self.sides.iter_mut().take(q.len()).enumerate() {
            *s = Side::of(q[k], *s);
        }
    }

    /// Sides of one interface's slots.
    pub fn of_interface(&self, model: &Model, interface: usize) -> &[Side] {
        &self.sides[model.interfaces[interface].slots.clone()]
    }
}
