//! eds2rust-machine: the seed machine, from `eds/machine/bus.yml`: the
//! Zimmer axis (node 40), the LINAK actuator (32) and the Interroll
//! conveyor (5) on one bus. Each node's module holds its typed object
//! dictionary and the PDOs the network configures; `network` the process
//! image (`Inputs`, `Outputs`) and the boot plan `network::PLAN`.
//!
//! A crate of its own (not a feature of eds2rust-drivers): its nodes repeat
//! the seed devices' types, which would otherwise sit beside them in one
//! crate.
#![no_std]
#![forbid(unsafe_code)]

include!(concat!(env!("OUT_DIR"), "/machine.rs"));

pub use eds2rust_runtime as runtime;
