//! GPU passes: each is one shader (or a few stages of one) plus one file here.

pub mod bssrdf_eval;
pub mod shade;
