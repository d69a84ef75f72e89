//! motion (see DESIGN.md).
