//! Dumps of the IR for tools and tests.

pub mod json;
