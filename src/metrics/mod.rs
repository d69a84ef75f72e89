//! metrics (see DESIGN.md).
