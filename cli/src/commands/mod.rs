//! One module per subcommand: each turns parsed arguments into work and prints the result.

pub mod convert;
pub mod decode;
pub mod encode;
pub mod eval;
pub mod info;
pub mod inspect;
