//! geometry_image (see DESIGN.md).
