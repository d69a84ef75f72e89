//! The `.mcgv` stream: the container (parts with checksums, knowing nothing of codecs), byte
//! serialisation, the entropy coder, and the parts every codec shares: header, frame index and
//! side information (partition, lattice coordinates, predictor).

pub mod affine_coding;
pub mod attributes;
pub mod bytes;
pub mod container;
pub mod entropy;
pub mod frame_index;
pub mod header;
pub mod lattice_coding;
mod part_table;
pub mod segments;
pub mod side_info;
mod texcoords;
