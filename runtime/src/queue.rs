//! A fixed-capacity FIFO queue without heap, shared by the protocol cores
//! for the frames and events they hand out.

/// FIFO of at most `N` values. [`Ring::push`] drops the oldest value when
/// full and counts it; [`Ring::try_push`] refuses instead.
#[derive(Debug, Clone)]
pub(crate) struct Ring<T, const N: usize> {
    slots: [Option<T>; N],
    head: usize,
    len: usize,
    dropped: u32,
}

impl<T, const N: usize> Ring<T, N> {
    /// An empty queue.
    pub(crate) const fn new() -> Self {
        Ring {
            slots: [const { None }; N],
            head: 0,
            len: 0,
            dropped: 0,
        }
    }

    /// Appends `value`, or gives it back when the queue is full.
    pub(crate) fn try_push(&mut self, value: T) -> Result<(), T> {
        if self.len >= N {
            return Err(value);
        }
        let Some(slot) = (self.head + self.len)
            .checked_rem(N)
            .and_then(|tail| self.slots.get_mut(tail))
        else {
            return Err(value);
        };
        *slot = Some(value);
        self.len += 1;
        Ok(())
    }

    /// Appends `value`; when full, the oldest value is dropped first (and
    /// counted in [`Ring::dropped`]).
    pub(crate) fn push(&mut self, value: T) {
        if self.len >= N && self.pop().is_some() {
            self.dropped = self.dropped.saturating_add(1);
        }
        if self.try_push(value).is_err() {
            // Only with N == 0: nothing can be stored.
            self.dropped = self.dropped.saturating_add(1);
        }
    }

    /// Removes and returns the oldest value.
    pub(crate) fn pop(&mut self) -> Option<T> {
        if self.len == 0 {
            return None;
        }
        let value = self.slots.get_mut(self.head).and_then(Option::take);
        self.head = (self.head + 1).checked_rem(N).unwrap_or(0);
        self.len -= 1;
        value
    }

    /// Number of values dropped by [`Ring::push`] so far.
    pub(crate) const fn dropped(&self) -> u32 {
        self.dropped
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ring_fifo_and_overflow() {
        let mut r: Ring<u8, 3> = Ring::new();
        assert_eq!(r.pop(), None);
        r.push(1);
        r.push(2);
        assert_eq!(r.pop(), Some(1));
        r.push(3);
        r.push(4);
        r.push(5);
        assert_eq!(r.dropped(), 1);
        assert_eq!(r.try_push(6), Err(6));
        assert_eq!(
            core::iter::from_fn(|| r.pop()).collect::<Vec<_>>(),
            [3, 4, 5]
        );
        let mut empty: Ring<u8, 0> = Ring::new();
        empty.push(1);
        assert_eq!((empty.pop(), empty.dropped()), (None, 1));
    }
}
