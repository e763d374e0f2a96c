//! eds2rust-sim: simulated CANopen devices, for examples, tests and
//! commissioning without hardware.
//!
//! - [`Device`] is a generic CiA 301 device built from a generated
//!   `od::OBJECTS` table: an SDO server over an [`ObjectTable`] that
//!   enforces access rights, types and limits; NMT slave with boot-up and
//!   heartbeat (0x1017), heartbeat consumer (0x1016), node guarding
//!   replies; TPDOs and RPDOs from
//!   the communication and mapping parameters in the table (reconfigurable
//!   over SDO with the CiA 301 rules); EMCY; SYNC; and, when configured,
//!   an LSS slave (CiA 305). It is a sans-IO [`Service`](eds2rust_runtime::Service)
//!   like the runtime's cores, so tests run it on a virtual clock and
//!   examples run it on a bus in a thread.
//! - A [`Behaviour`] adds what the device does: `models` (feature
//!   `seed-models`) has the three seed devices, written from their manuals.
//! - [`cia402`] is a generic CiA 402 drive behaviour for any table with a
//!   controlword and a statusword (docs/cia402-sim.md).
//! - `file` (feature `files`) reads the table of a device from an
//!   EDS/DCF/YAML file at run time, for devices without generated code.
//! - `network` (feature `files`) simulates every slave of a bus file,
//!   with faults (missing, wrong identity, late boot, power loss, SDO
//!   abort, heartbeat stop), as one service.
//! - [`bench`](mod@bench) runs a master and a device in virtual time, for tests.
//! - `boot_bench` (feature `files`) boots a generated network of many
//!   simulated slaves on the [`timed_bus`] and measures the boot against
//!   the least time its frames need on the wire.
//! - [`timed_bus`] runs a master and many devices on one bus in virtual
//!   time where every frame takes its bit time, one at a time (the boot
//!   benchmark's bus).
//! - [`harness`] runs a simulator and a master on the virtual bus (or, with
//!   the feature `socketcan`, on a SocketCAN interface), with an optional
//!   candump-style trace.
//!
//! Without features the crate needs nothing but the runtime: a crate that
//! simulates its own device passes its generated `od::OBJECTS` to
//! [`Device::new`] (see docs/simulators.md).
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod behaviour;
pub mod bench;
#[cfg(feature = "files")]
pub mod boot_bench;
pub mod cia402;
pub mod device;
#[cfg(feature = "files")]
pub mod file;
pub mod harness;
#[cfg(feature = "seed-models")]
pub mod models;
#[cfg(feature = "files")]
pub mod network;
pub mod program;
pub mod store;
pub mod timed_bus;

pub use behaviour::{Behaviour, Context};
pub use device::{Device, DeviceConfig, SimEvent};
pub use store::ObjectTable;
