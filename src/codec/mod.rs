//! codec (see DESIGN.md).

pub mod abbreviated;
