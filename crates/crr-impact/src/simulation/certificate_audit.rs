//! A check of the faces' certificate beside the simulation: wherever the uplift test in motion
//! lets the carried compressive distribution decide that nothing opens
//! ([`crate::face_forces::PressingCertificate::carries`]), the contact program is solved as well
//! and its answer, confirmed by the chain's exact solve, recorded when it opens or lifts
//! something. The certificate's answer is the one the run keeps, so a run audited and one not
//! audited are the same motion; the audit only says where the two would part.
//!
//! It is a developer's and a test's tool ([`super::Simulation::audit_certificate`]): it solves
//! one contact program at every certified step end, which is the cost the certificate saves.

use crr_kinematics::{Model, Side};

/// One state at which the certificate held and the contact program, confirmed by the chain's
/// exact solve, opened or lifted something.
#[derive(Clone, Debug, PartialEq)]
pub struct CertificateDisagreement {
    /// The time (s).
    pub t: f64,
    /// The slots the program releases and their sides, by their names ([`Model::slot_name`]
    /// of the chain integrated then).
    pub releases: Vec<(String, Side)>,
    /// The interfaces the program lifts off.
    pub lifting_off: Vec<String>,
    /// The locked solve's own error on the loops at that state: the largest closure row of
    /// Φ_q q̈ + Φ̇_q q̇ (m/s² for a corner row; an orientation row's 1/s² times the model size).
    /// Near a hyperstatic seat the closed-chain solve takes nearly dependent rows as dependent
    /// and leaves them open by this much; an opening rate (rad/s²) below it divided by the model
    /// size is within the solve's error.
    pub closure_residual: f64,
}

/// What the audit found over a run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CertificateAudit {
    /// Uplift tests in motion the certificate decided (nothing opens).
    pub certified: usize,
    /// Those at which the contact program disagreed, in time order.
    pub disagreements: Vec<CertificateDisagreement>,
    /// Those at which the contact program failed (no answer to compare).
    pub unsolved: usize,
    /// The largest locked solve's error on the loops over the certified states
    /// ([`CertificateDisagreement::closure_residual`]).
    pub largest_closure_residual: f64,
}

impl CertificateAudit {
    /// Records the program's answer at a certified state: `releases` as confirmed by the chain,
    /// `lifting_off` the interfaces it lifts off (their names).
    pub(super) fn record(
        &mut self,
        model: &Model,
        t: f64,
        releases: &[(usize, Side)],
        lifting_off: Vec<String>,
        closure_residual: f64,
    ) {
        self.certified += 1;
        self.largest_closure_residual = self.largest_closure_residual.max(closure_residual);
        if releases.is_empty() && lifting_off.is_empty() {
            return;
        }
        self.disagreements.push(CertificateDisagreement {
            t,
            releases: releases
                .iter()
                .map(|&(k, side)| (model.slot_name(k), side))
                .collect(),
            lifting_off,
            closure_residual,
        });
    }
}
