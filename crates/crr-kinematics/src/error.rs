//! The error a model description can produce: which item, and what is wrong with it.

/// An invalid model description: names the item (a body, an interface, a field) and the problem.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{item}: {problem}")]
pub struct ModelError {
    /// The item, e.g. `interface "base" (pivot_positive)` or `body "column"`.
    pub item: String,
    /// What is wrong, in words an engineer can act on.
    pub problem: String,
}

impl ModelError {
    /// An error about `item`.
    pub fn new(item: impl Into<String>, problem: impl Into<String>) -> Self {
        Self {
            item: item.into(),
            problem: problem.into(),
        }
    }
}
