//! Multi-chart parameterization seeded by the motion clusters (filled in by the atlas issue).
