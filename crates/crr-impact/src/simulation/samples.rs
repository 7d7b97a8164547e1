//! The output samples of a run, stored by columns: one vector per quantity, q and q̇ as
//! `samples × DOF` row-major blocks and the slot states as `samples × slots`. A sample is read
//! through [`Sample`], a view of one row. A run records thousands of samples: by columns they
//! cost a few pushes each and no allocation of their own, and a caller gets each quantity as one
//! contiguous array (a plot, a numpy array, a column of history.csv). The faces open at a sample
//! ([`FaceOpening`], none in most samples) are kept in one list with each sample's end in it.

use serde::Serialize;

use super::SlotState;
use crr_kinematics::short_copy::extend_short;

/// Where an open face's bodies are relative to each other: the separation of the face's
/// reference point P⁺ (its pivot with every angle on its positive side, world at rest) as the
/// child carries it from where the parent carries it, x_c(P⁺) − x_p(P⁺) in world axes (m).
///
/// The outputs give an open face's angles as its bodies' relative rotation only (its child
/// turned about P⁺); with this offset the child is where it is: for a face of the file's tree
/// every body below it moves by it ([`super::open_loops::body_offsets`]). Its component along
/// the parent's face normal is the face's opening at P⁺.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FaceOpening {
    /// The interface (index into the file's model's interfaces).
    pub interface: usize,
    /// x_c(P⁺) − x_p(P⁺), world axes (m).
    pub offset: [f64; 3],
}

/// One output sample: a view of one row of [`Samples`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Sample<'a> {
    /// Time (s).
    pub t: f64,
    /// q (rad).
    pub q: &'a [f64],
    /// q̇ (rad/s).
    pub qdot: &'a [f64],
    /// Kinetic energy T (J).
    pub kinetic: f64,
    /// U − U(rest) (J).
    pub potential: f64,
    /// Work done by the ground motion since the start (J).
    pub work_in: f64,
    /// Energy dissipated since the start, at impacts and by regularised laws (J).
    pub dissipated: f64,
    /// State of every angle slot.
    pub states: &'a [SlotState],
    /// The faces open at this sample, in interface order (empty when none is).
    pub openings: &'a [FaceOpening],
}

/// Output samples in time order, by columns (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Samples {
    dof: usize,
    slots: usize,
    t: Vec<f64>,
    q: Vec<f64>,
    qdot: Vec<f64>,
    kinetic: Vec<f64>,
    potential: Vec<f64>,
    work_in: Vec<f64>,
    dissipated: Vec<f64>,
    states: Vec<SlotState>,
    openings: Vec<FaceOpening>,
    /// Each sample's end in `openings`.
    openings_end: Vec<usize>,
}

impl Samples {
    /// No samples, of a model with `dof` coordinates and `slots` angle slots.
    pub fn new(dof: usize, slots: usize) -> Self {
        Self::with_capacity(dof, slots, 0)
    }

    /// [`Self::new`] with room for `capacity` samples, so that pushing that many does not
    /// reallocate.
    pub fn with_capacity(dof: usize, slots: usize, capacity: usize) -> Self {
        Self {
            dof,
            slots,
            t: Vec::with_capacity(capacity),
            q: Vec::with_capacity(capacity * dof),
            qdot: Vec::with_capacity(capacity * dof),
            kinetic: Vec::with_capacity(capacity),
            potential: Vec::with_capacity(capacity),
            work_in: Vec::with_capacity(capacity),
            dissipated: Vec::with_capacity(capacity),
            states: Vec::with_capacity(capacity * slots),
            openings: Vec::new(),
            openings_end: Vec::with_capacity(capacity),
        }
    }

    /// Number of coordinates of each sample's q and q̇.
    pub fn dof(&self) -> usize {
        self.dof
    }

    /// Number of angle slots of each sample's states.
    pub fn slots(&self) -> usize {
        self.slots
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether there is no sample.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// Sample `i`, if `i < len()`.
    pub fn get(&self, i: usize) -> Option<Sample<'_>> {
        if i >= self.len() {
            return None;
        }
        let (n, m) = (self.dof, self.slots);
        let start = if i == 0 { 0 } else { self.openings_end[i - 1] };
        Some(Sample {
            t: self.t[i],
            q: &self.q[i * n..(i + 1) * n],
            qdot: &self.qdot[i * n..(i + 1) * n],
            kinetic: self.kinetic[i],
            potential: self.potential[i],
            work_in: self.work_in[i],
            dissipated: self.dissipated[i],
            states: &self.states[i * m..(i + 1) * m],
            openings: &self.openings[start..self.openings_end[i]],
        })
    }

    /// The first sample.
    pub fn first(&self) -> Option<Sample<'_>> {
        self.get(0)
    }

    /// The last sample.
    pub fn last(&self) -> Option<Sample<'_>> {
        self.len().checked_sub(1).and_then(|i| self.get(i))
    }

    /// The samples in time order.
    pub fn iter(&self) -> Iter<'_> {
        Iter {
            samples: self,
            front: 0,
            back: self.len(),
        }
    }

    /// Times (s), one per sample.
    pub fn times(&self) -> &[f64] {
        &self.t
    }

    /// q of every sample, row-major (`len() × dof()`, rad).
    pub fn q(&self) -> &[f64] {
        &self.q
    }

    /// q̇ of every sample, row-major (`len() × dof()`, rad/s).
    pub fn qdot(&self) -> &[f64] {
        &self.qdot
    }

    /// Kinetic energies T (J).
    pub fn kinetic(&self) -> &[f64] {
        &self.kinetic
    }

    /// U − U(rest) (J).
    pub fn potential(&self) -> &[f64] {
        &self.potential
    }

    /// Work done by the ground motion since the start (J).
    pub fn work_in(&self) -> &[f64] {
        &self.work_in
    }

    /// Energy dissipated since the start (J).
    pub fn dissipated(&self) -> &[f64] {
        &self.dissipated
    }

    /// Slot states of every sample, row-major (`len() × slots()`).
    pub fn states(&self) -> &[SlotState] {
        &self.states
    }

    /// The open faces of every sample, in sample order (sample i's are
    /// [`Self::get`]`(i).openings`).
    pub fn openings(&self) -> &[FaceOpening] {
        &self.openings
    }

    /// Appends a sample.
    ///
    /// # Panics
    /// If `s.q` or `s.qdot` does not have `dof()` entries or `s.states` `slots()` entries.
    pub fn push(&mut self, s: Sample<'_>) {
        assert!(
            s.q.len() == self.dof && s.qdot.len() == self.dof && s.states.len() == self.slots,
            "a sample of {} coordinates, {} rates and {} slots pushed to samples of {} and {}",
            s.q.len(),
            s.qdot.len(),
            s.states.len(),
            self.dof,
            self.slots
        );
        self.t.push(s.t);
        extend_short(&mut self.q, s.q);
        extend_short(&mut self.qdot, s.qdot);
        self.kinetic.push(s.kinetic);
        self.potential.push(s.potential);
        self.work_in.push(s.work_in);
        self.dissipated.push(s.dissipated);
        extend_short(&mut self.states, s.states);
        self.openings.extend_from_slice(s.openings);
        self.openings_end.push(self.openings.len());
    }

    /// Appends every sample of `other` (e.g. the batches [`super::Simulation::drain_samples`]
    /// hands over, joined again).
    ///
    /// # Panics
    /// If `other`'s dimensions differ.
    pub fn append(&mut self, other: &Samples) {
        assert!(
            other.dof == self.dof && other.slots == self.slots,
            "samples of {} coordinates and {} slots appended to samples of {} and {}",
            other.dof,
            other.slots,
            self.dof,
            self.slots
        );
        self.t.extend_from_slice(&other.t);
        self.q.extend_from_slice(&other.q);
        self.qdot.extend_from_slice(&other.qdot);
        self.kinetic.extend_from_slice(&other.kinetic);
        self.potential.extend_from_slice(&other.potential);
        self.work_in.extend_from_slice(&other.work_in);
        self.dissipated.extend_from_slice(&other.dissipated);
        self.states.extend_from_slice(&other.states);
        let base = self.openings.len();
        self.openings.extend_from_slice(&other.openings);
        self.openings_end
            .extend(other.openings_end.iter().map(|&e| base + e));
    }

    /// Removes every sample, keeping the dimensions and the allocated capacity.
    pub fn clear(&mut self) {
        self.t.clear();
        self.q.clear();
        self.qdot.clear();
        self.kinetic.clear();
        self.potential.clear();
        self.work_in.clear();
        self.dissipated.clear();
        self.states.clear();
        self.openings.clear();
        self.openings_end.clear();
    }
}

impl<'a> IntoIterator for &'a Samples {
    type Item = Sample<'a>;
    type IntoIter = Iter<'a>;
    fn into_iter(self) -> Iter<'a> {
        self.iter()
    }
}

/// Iterator over [`Samples`] in time order (double-ended).
#[derive(Clone, Debug)]
pub struct Iter<'a> {
    samples: &'a Samples,
    front: usize,
    back: usize,
}

impl<'a> Iterator for Iter<'a> {
    type Item = Sample<'a>;
    fn next(&mut self) -> Option<Sample<'a>> {
        if self.front >= self.back {
            return None;
        }
        self.front += 1;
        self.samples.get(self.front - 1)
    }
    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = self.back - self.front;
        (n, Some(n))
    }
}

impl DoubleEndedIterator for Iter<'_> {
    fn next_back(&mut self) -> Option<Self::Item> {
        if self.front >= self.back {
            return None;
        }
        self.back -= 1;
        self.samples.get(self.back)
    }
}

impl ExactSizeIterator for Iter<'_> {}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(k: usize) -> (f64, [f64; 2], [f64; 2], [SlotState; 1]) {
        let x = k as f64;
        (
            0.1 * x,
            [x, -x],
            [2.0 * x, 3.0 * x],
            [if k.is_multiple_of(2) {
                SlotState::Positive
            } else {
                SlotState::Seated
            }],
        )
    }

    /// Rows pushed are read back unchanged, by index, forwards and backwards and by columns.
    #[test]
    fn rows_read_back_as_pushed() {
        let mut s = Samples::new(2, 1);
        assert!(s.is_empty() && s.first().is_none() && s.last().is_none());
        let rows: Vec<_> = (0..5).map(row).collect();
        let opened = [FaceOpening {
            interface: 2,
            offset: [1.0, 0.0, -1.0],
        }];
        for (k, (t, q, qd, st)) in rows.iter().enumerate() {
            s.push(Sample {
                t: *t,
                q,
                qdot: qd,
                kinetic: k as f64,
                potential: -(k as f64),
                work_in: 0.5 * k as f64,
                dissipated: 0.25 * k as f64,
                states: st,
                openings: if k == 3 { &opened } else { &[] },
            });
        }
        assert_eq!(s.len(), 5);
        for (k, x) in s.iter().enumerate() {
            let (t, q, qd, st) = &rows[k];
            assert_eq!((x.t, x.q, x.qdot, x.states), (*t, &q[..], &qd[..], &st[..]));
            assert_eq!(x.kinetic, k as f64);
            assert_eq!(x.potential, -(k as f64));
            assert_eq!(x.work_in, 0.5 * k as f64);
            assert_eq!(x.dissipated, 0.25 * k as f64);
            assert_eq!(s.get(k), Some(x));
            assert_eq!(x.openings, if k == 3 { &opened[..] } else { &[] });
        }
        let mut twice = s.clone();
        twice.append(&s);
        assert_eq!(twice.get(8).unwrap().openings, &opened[..]);
        assert!(twice.get(7).unwrap().openings.is_empty());
        let back: Vec<f64> = s.iter().rev().map(|x| x.t).collect();
        assert_eq!(back, rows.iter().rev().map(|r| r.0).collect::<Vec<_>>());
        assert_eq!(s.iter().len(), 5);
        assert_eq!(s.last().unwrap().t, rows[4].0);
        assert!(s.get(5).is_none());
        assert_eq!(&s.q()[6..8], &rows[3].1[..]);
        assert_eq!(s.times().len(), 5);
        s.clear();
        assert!(s.is_empty() && s.dof() == 2 && s.slots() == 1);
    }

    #[test]
    #[should_panic(expected = "a sample of 1 coordinates, 1 rates and 0 slots")]
    fn a_row_of_the_wrong_width_is_refused() {
        let mut s = Samples::new(2, 0);
        s.push(Sample {
            t: 0.0,
            q: &[0.0],
            qdot: &[0.0],
            kinetic: 0.0,
            potential: 0.0,
            work_in: 0.0,
            dissipated: 0.0,
            states: &[],
            openings: &[],
        });
    }
}
