//! stream (see DESIGN.md).

pub mod entropy;
pub mod first_frame;
