//! eds2rust-runtime: the thin CANopen runtime that generated drivers talk through.
//!
//! Now:
//! - [`od`]: the object-dictionary traits and types that generated code
//!   implements (entries as zero-sized types with type-level access rights,
//!   value conversion, PDO structs, node ids). Needs only `core`.
//!
//! To come (issues 5 and 6 of the project plan): sans-IO protocol cores fed
//! with frames and time (NMT, heartbeat, SDO client and server, PDO engine,
//! SYNC, EMCY, LSS master, a CiA 402 helper) and transports (Linux SocketCAN,
//! any `embedded-can` device, an in-process virtual bus with simulators).
#![no_std]

pub mod od;
