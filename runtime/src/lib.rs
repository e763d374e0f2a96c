//! eds2rust-runtime: the thin CANopen runtime that generated drivers talk through.
//!
//! This crate will hold (issue 5 and 6 of the project plan):
//! - `frame`: classic CAN frames and COB-ID helpers;
//! - sans-IO protocol cores fed with frames and time: NMT master and node-state
//!   tracking, heartbeat producer/consumer, SDO client and server (expedited,
//!   segmented, block), PDO engine, SYNC producer, EMCY consumer, LSS master,
//!   a CiA 402 drive state-machine helper;
//! - transports: Linux SocketCAN (blocking and tokio), any `embedded-can`
//!   device, and an in-process virtual bus with device simulators.
//!
//! Nothing is implemented yet; the crate exists so that the workspace layout of
//! DESIGN.md is in place and downstream paths are stable.
#![no_std]
