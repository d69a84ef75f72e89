//! The `.mcgv` stream: container, byte serialisation, entropy coding and the parts it holds.

pub mod bytes;
pub mod container;
pub mod entropy;
pub mod first_frame;
pub mod frame_index;
pub mod header;
pub mod side_info;
pub mod tdct;
