//! Behaviour models of the seed devices, each written from its manual (the
//! German manuals in ../shared/seeds; the transcribed tables are in eds/ and
//! docs/devices/).

pub mod interroll_ec5000bi;
pub mod linak_techline;
pub mod zimmer_acs;
