//! A fixed-capacity FIFO for the frames and events the server hands out
//! (no allocation; when full, the oldest item is dropped).

/// First-in first-out queue of at most `N` items.
#[derive(Debug)]
pub(super) struct Ring<T, const N: usize> {
    items: [Option<T>; N],
    /// Slot of the oldest item.
    head: usize,
    len: usize,
}

impl<T, const N: usize> Ring<T, N> {
    pub(super) fn new() -> Self {
        Ring {
            items: core::array::from_fn(|_| None),
            head: 0,
            len: 0,
        }
    }

    /// Appends `item`; when the queue is full the oldest item makes room.
    pub(super) fn push(&mut self, item: T) {
        if N == 0 {
            return;
        }
        if self.len == N {
            self.head = (self.head + 1) % N;
            self.len -= 1;
        }
        let slot = (self.head + self.len) % N;
        if let Some(cell) = self.items.get_mut(slot) {
            *cell = Some(item);
            self.len += 1;
        }
    }

    /// Removes and returns the oldest item.
    pub(super) fn pop(&mut self) -> Option<T> {
        if self.len == 0 {
            return None;
        }
        let item = self.items.get_mut(self.head)?.take();
        self.head = (self.head + 1) % N;
        self.len -= 1;
        item
    }
}

#[cfg(test)]
mod tests {
    use super::Ring;

    #[test]
    fn fifo_order_and_overflow_drops_the_oldest() {
        let mut ring: Ring<u8, 3> = Ring::new();
        assert_eq!(ring.pop(), None);
        ring.push(1);
        ring.push(2);
        assert_eq!(ring.pop(), Some(1));
        ring.push(3);
        ring.push(4);
        ring.push(5);
        assert_eq!(ring.pop(), Some(3));
        assert_eq!(ring.pop(), Some(4));
        assert_eq!(ring.pop(), Some(5));
        assert_eq!(ring.pop(), None);
    }
}
