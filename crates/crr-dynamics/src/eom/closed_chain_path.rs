//! The closed-chain path of [`Dynamics`]: Gauss' principle on the constraint rows (loop
//! closures and seated closure angles), through the Cholesky factor of M and either the selected
//! independent rows ([`super::selected_rows`]) or the Jacobi SVD of B; the tree reactions.

use super::*;

impl Dynamics {
    /// The solve of [`Self::accelerations_with`] on the state last given to [`Self::evaluate`]:
    /// q̈, λ and the seat reactions for the current seated slots. The kinematics, M, h and Q do
    /// not depend on which slots are seated, so that trying several seated sets at one state
    /// (the uplift test) evaluates them once.
    pub fn solve_evaluated(
        &mut self,
        model: &Model,
        t: f64,
        q: &DVector<f64>,
        qdot: &DVector<f64>,
        extra: Option<&mut dyn GeneralizedForce>,
    ) -> Result<(), DynamicsError> {
        if self.articulated_applies(model) {
            return self.solve_articulated(model, t, q, qdot, extra);
        }
        self.used_articulated = false;
        self.used_single_coordinate = false;
        self.used_selected = false;
        self.factorise(model)?;
        self.add_extra_force(model, t, q, qdot, extra);
        // r = Q + F_extra − h: the generalized force left for inertia and constraints.
        self.residual.copy_from(&self.load);
        self.residual += &self.extra_force;
        self.residual -= &self.kin.velocity_product;
        self.solve_rows(model, t, true)
    }

    /// The velocity an impulse leaves on the state last given to [`Self::evaluate`]: Gauss'
    /// principle of impulsive motion, M q̇⁺ = p + Φ'ᵀΛ with Φ' q̇⁺ = 0 over the closure rows and
    /// the rate rows of the seated slots (the seated tree coordinates of an open chain keep
    /// q̇ = 0 by elimination). `p` is the generalized momentum the bodies carry into the impact;
    /// q̇⁺ is the velocity of the constrained chain nearest M⁻¹p in the kinetic metric, i.e. the
    /// plastic impact on those rows. The same factorisations and selected rows as the
    /// accelerations (no SVD while the selected rows stay independent). Returns q̇⁺; the impulses
    /// Λ are left in `lambda` and `seat_reactions`.
    pub fn solve_impulse(
        &mut self,
        model: &Model,
        t: f64,
        p: &DVector<f64>,
    ) -> Result<&DVector<f64>, DynamicsError> {
        self.used_articulated = false;
        self.used_single_coordinate = false;
        self.used_selected = false;
        self.factorise(model)?;
        self.residual.copy_from(p);
        self.solve_rows(model, t, false)?;
        Ok(&self.qddot)
    }

    /// Gauss' principle on the constraint rows for the generalized force in `residual`, after
    /// [`Self::factorise`]: q̈ (or q̇⁺) into `qddot`, the multipliers into `lambda` and
    /// `seat_reactions`. `with_bias`: the rows' right-hand sides are −(Φ̇_q q̇) (accelerations);
    /// without, 0 (impulses).
    fn solve_rows(&mut self, model: &Model, t: f64, with_bias: bool) -> Result<(), DynamicsError> {
        let n = model.dof();
        let nf = self.free.len();
        // Gauss' principle in the coordinates z = Lᵀq̈_f (M_ff = L Lᵀ): z is the point of the
        // affine set B z = −c nearest to z_free = L⁻¹ r_f, with B = Φ'_f L⁻ᵀ the row-scaled closures
        // and the seated rows not eliminated, over the free columns. Decomposing B (rows × free) rather
        // than B Bᵀ keeps the conditioning unsquared and the matrix small when many rows are
        // redundant.
        self.z.resize_vertically_mut(nf, 0.0);
        for (i, &k) in self.free.iter().enumerate() {
            self.z[i] = self.residual[k];
        }
        self.factor.forward(self.z.as_mut_slice());
        let seated_rows = self.seated.iter().filter(|&&s| self.is_row(s)).count();
        let rows = model.constraint_rows + seated_rows;
        if rows == 0 {
            self.factor.backward_transposed(self.z.as_mut_slice());
            self.scatter_accelerations();
            self.lambda.fill(0.0);
            self.seat_reactions
                .resize_vertically_mut(self.seated.len(), 0.0);
            self.tree_reactions(None);
            return self.check_finite(t);
        }
        // The rows over every coordinate (row-scaled Φ_q, the seated slots' rate rows), each on
        // its structural pattern, and their right-hand sides.
        let mut bias = DVector::zeros(rows);
        self.gather_rows(model, with_bias, &mut bias);
        // With seated coordinates eliminated, B's own σ_max can be round-off (a loop whose free
        // coordinates do not enter its closure here): the rank threshold is then taken against the
        // whole row-scaled Jacobian with every column, Jacobi-scaled by M's diagonal
        // (‖Φ'_j‖/√M_jj, the size of B's column j), so that noise is never inverted.
        let mut floor = 0.0;
        if nf < n {
            // Σ_j ‖Φ'_j‖²/M_jj, the columns' squares summed first (in `dense_row`, free here).
            let columns = &mut self.dense_row;
            columns.fill(0.0);
            for i in 0..rows {
                for &(j, v) in self.rows_full.row(i) {
                    columns[j] += v * v;
                }
            }
            let whole: f64 = (0..n)
                .filter(|&j| columns[j] != 0.0)
                .map(|j| columns[j] / self.kin.mass_matrix[(j, j)])
                .sum();
            floor = RANK_TOLERANCE.sqrt() * whole.sqrt();
        }
        // B = (rows over the free columns) L⁻ᵀ, row by row: each row's pattern is closed under
        // the tree's parents, so L⁻¹ keeps it (`forward_on`).
        self.rows_b.clear(nf);
        self.spread.clear();
        self.spread.resize(nf, 0.0);
        for i in 0..rows {
            self.pattern.clear();
            for &(k, v) in self.rows_full.row(i) {
                let p = self.free_position[k];
                if p != usize::MAX {
                    self.pattern.push(p);
                    self.spread[p] = v;
                }
            }
            // `free` runs down the coordinates, so ascending coordinates give descending
            // positions.
            self.pattern.reverse();
            debug_assert!(self.pattern.windows(2).all(|w| w[0] < w[1]));
            self.factor.forward_on(&self.pattern, &mut self.spread);
            let spread = &mut self.spread;
            self.rows_b.push_row(
                self.pattern
                    .iter()
                    .map(|&p| (p, std::mem::take(&mut spread[p])))
                    .filter(|(_, v)| *v != 0.0),
            );
        }
        // e = B z + bias: the constraint residual at z_free (in `bias`'s storage).
        let mut residual = bias;
        for i in 0..rows {
            residual[i] += self.rows_b.dot(i, self.z.as_slice());
        }
        let cached = self
            .selections
            .iter()
            .position(|sel| sel.rows == rows && sel.free == nf && sel.seated == self.seated);
        let mut dz = DVector::zeros(nf);
        let mut lambda_scaled = DVector::zeros(rows);
        let mut solve_on = |rows_work: &mut SelectedRowsWork, selected: &[usize]| {
            solve_selected_rows(
                rows_work,
                &self.rows_b,
                &residual,
                selected,
                RANK_TOLERANCE.sqrt(),
                floor,
                self.min_norm_multipliers,
                &mut dz,
                &mut lambda_scaled,
            )
        };
        let mut fast = false;
        if self.closed_chain_solve == ClosedChainSolve::SelectedRows {
            fast =
                cached.is_some_and(|c| solve_on(&mut self.rows_work, &self.selections[c].selected));
            if !fast && cached.is_none() {
                // A new seated set: rows chosen by Gram–Schmidt with pivoting against the same
                // threshold, kept if the solve certifies them; the SVD only where it does not.
                let threshold = (RANK_TOLERANCE.sqrt() * self.rows_b.norm()).max(floor);
                let selected = pivot_columns_above(&self.rows_b.dense_transposed(), threshold);
                fast = solve_on(&mut self.rows_work, &selected);
                if fast {
                    self.remember_selection(None, rows, nf, selected);
                }
            }
        }
        self.used_selected = fast;
        if !fast {
            let bt = self.rows_b.dense_transposed();
            let svd = JacobiSvd::thin(&bt.transpose());
            // The threshold of the former solve on B Bᵀ (σ(BBᵀ) = σ(B)²): same rank decisions.
            let tol = svd.tolerance_relative(RANK_TOLERANCE.sqrt()).max(floor);
            dz = -svd.solve_with(&residual, tol);
            // z − z_free = Bᵀ λ': the minimum-norm multipliers.
            lambda_scaled = svd.solve_transposed_with(&dz, tol);
            if self.closed_chain_solve == ClosedChainSolve::SelectedRows {
                let rank = svd.singular_values.iter().filter(|s| **s > tol).count();
                self.remember_selection(cached, rows, nf, pivot_columns(&bt, rank));
            }
        }
        self.z += &dz;
        self.factor.backward_transposed(self.z.as_mut_slice());
        self.scatter_accelerations();
        self.lambda = lambda_scaled
            .rows(0, model.constraint_rows)
            .component_mul(&self.row_scale);
        let row_reactions = lambda_scaled.rows(model.constraint_rows, seated_rows);
        // Seat reactions in the order of `seated`: tree coordinates from their rows' residuals
        // (below), closure angles from the decomposition.
        self.seat_reactions
            .resize_vertically_mut(self.seated.len(), 0.0);
        let mut a = 0;
        for (i, &s) in self.seated.iter().enumerate() {
            if self.is_row(s) {
                self.seat_reactions[i] = row_reactions[a];
                a += 1;
            }
        }
        // The generalized force of every row's multiplier, Φ_qᵀλ plus the seated rows' (the
        // scaled rows times the scaled multipliers), over the rows' patterns.
        let mut row_force = DVector::zeros(n);
        for i in 0..rows {
            for &(j, v) in self.rows_full.row(i) {
                row_force[j] += v * lambda_scaled[i];
            }
        }
        self.tree_reactions(Some(&row_force));
        self.check_finite(t)
    }

    /// Keeps the rows `selected` for the current seated set, in place of the selection at
    /// `cached` (one that failed), or as a new entry (the oldest evicted once the cache is
    /// full).
    fn remember_selection(
        &mut self,
        cached: Option<usize>,
        rows: usize,
        free: usize,
        selected: Vec<usize>,
    ) {
        let selection = RowSelection {
            rows,
            free,
            seated: self.seated.clone(),
            selected,
        };
        match cached {
            Some(c) => self.selections[c] = selection,
            None if self.selections.len() < SELECTION_CACHE => self.selections.push(selection),
            None => {
                self.selections[self.next_evicted] = selection;
                self.next_evicted = (self.next_evicted + 1) % SELECTION_CACHE;
            }
        }
    }

    /// The constraint rows over every coordinate into `rows_full`, each on its structural
    /// pattern (columns ascending): the row-scaled rows of Φ_q (a closure's rows on the paths
    /// of its two frames to the ground, a symmetry row on its two coordinates), then the rate
    /// rows of the seated slots held by rows (a tree coordinate's eₖ, a closure angle's on its
    /// interface's frame paths). Their right-hand sides into `bias` when `with_bias`.
    fn gather_rows(&mut self, model: &Model, with_bias: bool, bias: &mut DVector<f64>) {
        let n = model.dof();
        self.rows_full.clear(n);
        // The closures hold consecutive rows in their order (`Closure::first_row`, `rows`); their
        // patterns depend on the tree alone and are found once.
        let known = self.closure_paths.len() == model.closures.len()
            && model
                .closures
                .iter()
                .zip(&self.closure_paths)
                .all(|(cl, (interface, _))| cl.interface == *interface);
        if !known {
            self.closure_paths = model
                .closures
                .iter()
                .map(|cl| {
                    let mut path = Vec::new();
                    frame_paths(model, cl.interface, &mut path);
                    (cl.interface, path)
                })
                .collect();
        }
        for (cl, (_, path)) in model.closures.iter().zip(&self.closure_paths) {
            debug_assert_eq!(cl.first_row, self.rows_full.rows());
            for i in cl.first_row..cl.first_row + cl.rows {
                let scale = self.row_scale[i];
                let phi_q = &self.kin.phi_q;
                self.rows_full
                    .push_row(path.iter().map(|&k| (k, scale * phi_q[(i, k)])));
            }
        }
        for (k, &(a, b, _)) in model.symmetries.iter().enumerate() {
            let i = model.closure_rows + k;
            coordinate_paths(model, &[a, b], &mut self.path);
            let scale = self.row_scale[i];
            let phi_q = &self.kin.phi_q;
            self.rows_full
                .push_row(self.path.iter().map(|&k| (k, scale * phi_q[(i, k)])));
        }
        debug_assert_eq!(self.rows_full.rows(), model.constraint_rows);
        if with_bias {
            bias.rows_mut(0, model.constraint_rows)
                .copy_from(&self.kin.phi_bias.component_mul(&self.row_scale));
        }
        let mut row = std::mem::take(&mut self.dense_row);
        row.resize_vertically_mut(n, 0.0);
        let mut k = 0;
        for index in 0..self.seated.len() {
            let slot = self.seated[index];
            if !self.is_row(slot) {
                continue;
            }
            let row_bias = slot_row(model, &self.kin, slot, &mut row);
            if with_bias {
                bias[model.constraint_rows + k] = row_bias;
            }
            if slot < n {
                coordinate_paths(model, &[slot], &mut self.path);
            } else {
                let interface = model
                    .interfaces
                    .iter()
                    .position(|f| f.slots.contains(&slot))
                    .expect("a closure slot belongs to an interface");
                frame_paths(model, interface, &mut self.path);
            }
            self.rows_full
                .push_row(self.path.iter().map(|&j| (j, row[j])));
            k += 1;
        }
        self.dense_row = row;
    }

    /// Sets `extra_force` to the extra generalized force at this state (0 without one).
    pub(super) fn add_extra_force(
        &mut self,
        model: &Model,
        t: f64,
        q: &DVector<f64>,
        qdot: &DVector<f64>,
        extra: Option<&mut dyn GeneralizedForce>,
    ) {
        self.extra_force.fill(0.0);
        if let Some(f) = extra {
            f.add(model, &self.kin, t, q, qdot, &mut self.extra_force);
        }
    }

    /// True if seated slot `s` is held by a constraint row (a closure angle, or any slot of a
    /// closed chain), false if eliminated (a tree coordinate of an open chain).
    pub(super) fn is_row(&self, s: usize) -> bool {
        s >= self.locked.len() || !self.locked[s]
    }

    /// Writes q̈ from the free accelerations in `z` (seated tree coordinates: 0).
    pub(super) fn scatter_accelerations(&mut self) {
        self.qddot.fill(0.0);
        for (i, &k) in self.free.iter().enumerate() {
            self.qddot[k] = self.z[i];
        }
    }

    /// Reactions of the eliminated seated coordinates: the residual of their rows of the
    /// equations of motion, M_k· q̈ − r_k − (`row_force`)_k (Φ_qᵀλ and the seated rows' force,
    /// none without constraint rows), written at their
    /// places in `seat_reactions` (sized to `seated`). q̈ vanishes on the seated coordinates, so
    /// M_k· q̈ sums over the free ones only.
    pub(super) fn tree_reactions(&mut self, row_force: Option<&DVector<f64>>) {
        for (i, &s) in self.seated.iter().enumerate() {
            if self.is_row(s) {
                continue;
            }
            let inertial: f64 = self
                .free
                .iter()
                .map(|&j| self.kin.mass_matrix[(s, j)] * self.qddot[j])
                .sum();
            let mut reaction = inertial - self.residual[s];
            if let Some(f) = row_force {
                reaction -= f[s];
            }
            self.seat_reactions[i] = reaction;
        }
    }
}

/// The coordinates on the paths to the ground of an interface's parent and child frames (its
/// closure rows' and angle rows' structural pattern), ascending, into `out`.
fn frame_paths(model: &Model, interface: usize, out: &mut Vec<usize>) {
    let iface = &model.interfaces[interface];
    let child = model.body_coord[iface.child];
    match model.frame_of(iface.parent) {
        Some(parent) => coordinate_paths(model, &[parent, child], out),
        None => coordinate_paths(model, &[child], out),
    }
}

/// The coordinates `from` and their ancestors, ascending, into `out`: a pattern closed under
/// the tree's parents, which L⁻¹ keeps ([`SparseCholesky::forward_on`]; a row's own nonzeros
/// may be fewer, the rest are filled by L⁻¹ or stay zero).
fn coordinate_paths(model: &Model, from: &[usize], out: &mut Vec<usize>) {
    out.clear();
    for &start in from {
        let mut j = Some(start);
        while let Some(k) = j {
            out.push(k);
            j = model.coords[k].parent;
        }
    }
    out.sort_unstable();
    out.dedup();
}
