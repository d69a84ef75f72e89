//! stream (see DESIGN.md).
