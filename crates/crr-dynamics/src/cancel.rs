//! A request to stop a computation (a run, a check, a study), shared between the computation and
//! whoever may interrupt it: the integrator reads it after each accepted step, the statics
//! before each linear program, and the command line's signal handler and the Python bindings'
//! Ctrl-C set it.
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// A request to stop, shared between the work and whoever may interrupt it (a signal handler,
/// another thread): cloning it shares the flag, and two are equal where they share it.
#[derive(Clone, Debug, Default)]
pub struct Cancel(Arc<AtomicBool>);

impl Cancel {
    /// A request not made yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Asks every computation holding this flag to stop at its next check: the integrator
    /// after the step under way, the statics after the program under way.
    pub fn cancel(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    /// Whether [`Self::cancel`] was called.
    pub fn is_cancelled(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

impl PartialEq for Cancel {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

#[cfg(test)]
mod tests {
    use super::Cancel;

    /// A clone shares the request; a new one does not.
    #[test]
    fn clones_share_the_request() {
        let a = Cancel::new();
        let b = a.clone();
        let c = Cancel::new();
        assert!(!b.is_cancelled());
        a.cancel();
        assert!(b.is_cancelled() && !c.is_cancelled());
        assert_eq!(a, b);
        assert_ne!(a, c);
    }
}
