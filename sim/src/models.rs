//! Behaviour models of the seed devices, each written from its manual (the
//! German manuals in ../shared/seeds; the transcribed tables are in eds/ and
//! docs/devices/).

pub mod interroll_ec5000bi;
pub mod linak_techline;
pub mod zimmer_acs;

/// `v` moved towards `target` by at most `step` (a speed ramp of the
/// models' mechanics).
pub(crate) fn toward(v: f64, target: f64, step: f64) -> f64 {
    if (target - v).abs() <= step {
        target
    } else if target > v {
        v + step
    } else {
        v - step
    }
}
