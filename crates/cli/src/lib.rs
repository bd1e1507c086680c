//! The `polepatch` command line's library part: file jobs (read, patch through
//! [`polepatch::patch_nc_to`], write by the output policy of [`outputs`]) and the quality suite behind
//! `polepatch bench`. The pipeline itself lives in the `polepatch` library crate.

pub mod bench;
pub mod files;
pub mod outputs;
