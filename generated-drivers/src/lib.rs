//! eds2rust-drivers: typed drivers for the devices described in `eds/`.
//!
//! This crate will generate, through its own `build.rs` and the same builder
//! API a downstream crate uses, one module per device input in `eds/` (the
//! Zimmer ACS40/60 axis, the LINAK TECHLINE actuators and the Interroll
//! RollerDrive EC5000 BI). The generated code needs only `core`. Nothing is
//! generated yet.
#![no_std]
