//! What the trace readers' unit tests share: frame builders and a small
//! deterministic generator of random input.

use crate::{CanId, Frame};

/// A standard data frame.
pub(crate) fn std_frame(id: u16, data: &[u8]) -> Frame {
    Frame::new(CanId::Standard(id), data).unwrap()
}

/// An extended data frame.
pub(crate) fn ext_frame(id: u32, data: &[u8]) -> Frame {
    Frame::new(CanId::Extended(id), data).unwrap()
}

/// A small deterministic generator (xorshift64): the random-input tests
/// stay reproducible.
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    pub(crate) fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// A number below `n`.
    pub(crate) fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}
