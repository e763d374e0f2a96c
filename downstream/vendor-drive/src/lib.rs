//! The Elmo Gold drive's object dictionary, generated at build time.
#![no_std]
#![forbid(unsafe_code)]

pub mod drive {
    include!(concat!(env!("OUT_DIR"), "/drive.rs"));
}
