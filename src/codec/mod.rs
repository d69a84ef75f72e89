//! codec (see DESIGN.md).
