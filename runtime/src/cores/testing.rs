//! Test helpers shared by the cores' unit tests: the frames, instants and
//! node ids the tests are written in, and draining a core's output.

use crate::od::NodeId;
use crate::{CanId, Frame, Instant, Service};

/// Node `n` (1 to 127).
pub(crate) fn node(n: u8) -> NodeId {
    NodeId::new(n).unwrap()
}

/// A data frame on the 11-bit identifier `id`.
pub(crate) fn data(id: u16, bytes: &[u8]) -> Frame {
    Frame::new(CanId::Standard(id), bytes).unwrap()
}

/// A remote frame on the 11-bit identifier `id`, DLC 1.
pub(crate) fn rtr(id: u16) -> Frame {
    Frame::remote(CanId::Standard(id), 1).unwrap()
}

/// `n` milliseconds after the epoch.
pub(crate) fn ms(n: u64) -> Instant {
    Instant::from_millis(n)
}

/// Every frame `s` has to send.
pub(crate) fn frames<S: Service>(s: &mut S) -> Vec<Frame> {
    core::iter::from_fn(|| s.poll_transmit()).collect()
}

/// Every event `s` has to report.
pub(crate) fn events<S: Service>(s: &mut S) -> Vec<S::Event> {
    core::iter::from_fn(|| s.poll_event()).collect()
}

/// `s` is due at `due` ms: it says so, has nothing to send a millisecond
/// before, and sends `sent` at `due`.
pub(crate) fn assert_due<S: Service>(s: &mut S, due: u64, sent: &[Frame]) {
    assert_eq!(s.poll_timeout(), Some(ms(due)));
    s.handle_timeout(ms(due - 1));
    assert!(frames(s).is_empty());
    s.handle_timeout(ms(due));
    assert_eq!(frames(s), sent);
}
