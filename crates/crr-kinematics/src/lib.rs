//! x
pub mod shapes;
