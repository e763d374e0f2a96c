//! The frames the client has built and the caller has not taken yet.

/// Frames the client holds for [`Service::poll_transmit`]; a caller that
/// drains after every input never has more than two waiting.
pub(super) const TX_SLOTS: usize = 4;

/// Frames waiting for [`Service::poll_transmit`], oldest first. When full
/// (the caller stopped draining), the oldest frame is dropped.
#[derive(Debug)]
pub(super) struct TxQueue {
    frames: [[u8; 8]; TX_SLOTS],
    head: usize,
    len: usize,
}

impl TxQueue {
    pub(super) const fn new() -> TxQueue {
        TxQueue {
            frames: [[0; 8]; TX_SLOTS],
            head: 0,
            len: 0,
        }
    }

    pub(super) fn push(&mut self, frame: [u8; 8]) {
        if self.len == TX_SLOTS {
            self.head = (self.head + 1) % TX_SLOTS;
            self.len -= 1;
        }
        if let Some(slot) = self.frames.get_mut((self.head + self.len) % TX_SLOTS) {
            *slot = frame;
            self.len += 1;
        }
    }

    pub(super) fn pop(&mut self) -> Option<[u8; 8]> {
        if self.len == 0 {
            return None;
        }
        let frame = self.frames.get(self.head).copied();
        self.head = (self.head + 1) % TX_SLOTS;
        self.len -= 1;
        frame
    }
}
