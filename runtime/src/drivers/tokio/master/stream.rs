//! The receiving ends of the tokio [`super::Master`]: [`Events`] (every
//! [`MasterEvent`] no call waited for) and [`Pdos`] (one PDO, decoded).
//!
//! Each is a bounded queue of its own that the driver fills: when it is
//! full, the oldest item is dropped and counted ([`Events::dropped`],
//! [`Pdos::dropped`]), as the blocking master's queue does. An item leaves
//! the queue only in the poll that returns it, so dropping a pending
//! `next()` future loses nothing (cancellation-safe).

use core::future::poll_fn;
use core::marker::PhantomData;
use core::pin::Pin;
use core::task::{Context, Poll, Waker};
use std::collections::VecDeque;
use std::sync::{Mutex, MutexGuard, PoisonError};

use futures_core::Stream;

use crate::CanId;
use crate::master::MasterEvent;
use crate::od::{self, PdoLengthError};
use crate::pdo::PdoEvent;

/// A bounded queue filled by the driver and drained by one receiver.
#[derive(Debug)]
pub(super) struct Queue<T> {
    inner: Mutex<QueueState<T>>,
}

#[derive(Debug)]
struct QueueState<T> {
    items: VecDeque<T>,
    capacity: usize,
    dropped: u64,
    waker: Option<Waker>,
    closed: bool,
}

impl<T> Queue<T> {
    /// An empty open queue keeping at most `capacity` items (at least 1).
    pub(super) fn new(capacity: usize) -> Queue<T> {
        Queue {
            inner: Mutex::new(QueueState {
                items: VecDeque::new(),
                capacity: capacity.max(1),
                dropped: 0,
                waker: None,
                closed: false,
            }),
        }
    }

    fn lock(&self) -> MutexGuard<'_, QueueState<T>> {
        // Every update is a single push or pop: a poisoned lock is still good.
        self.inner.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Appends `item`, dropping (and counting) the oldest when full.
    pub(super) fn push(&self, item: T) {
        let mut state = self.lock();
        if state.closed {
            return;
        }
        if state.items.len() >= state.capacity {
            state.items.pop_front();
            state.dropped = state.dropped.saturating_add(1);
        }
        state.items.push_back(item);
        let waker = state.waker.take();
        drop(state);
        if let Some(waker) = waker {
            waker.wake();
        }
    }

    /// Ends the queue: once drained, the receiver yields `None`.
    pub(super) fn close(&self) {
        let mut state = self.lock();
        state.closed = true;
        let waker = state.waker.take();
        drop(state);
        if let Some(waker) = waker {
            waker.wake();
        }
    }

    fn poll_pop(&self, cx: &mut Context<'_>) -> Poll<Option<T>> {
        let mut state = self.lock();
        if let Some(item) = state.items.pop_front() {
            return Poll::Ready(Some(item));
        }
        if state.closed {
            return Poll::Ready(None);
        }
        state.waker = Some(cx.waker().clone());
        Poll::Pending
    }

    fn try_pop(&self) -> Option<T> {
        self.lock().items.pop_front()
    }

    fn len(&self) -> usize {
        self.lock().items.len()
    }

    fn dropped(&self) -> u64 {
        self.lock().dropped
    }

    fn set_capacity(&self, capacity: usize) {
        let mut state = self.lock();
        state.capacity = capacity.max(1);
        while state.items.len() > state.capacity {
            state.items.pop_front();
            state.dropped = state.dropped.saturating_add(1);
        }
    }

    fn is_closed(&self) -> bool {
        self.lock().closed
    }
}

/// The methods [`Events`] and [`Pdos`] share: the size of their queue
/// (of `$items`, one `$item` each) and what it dropped.
macro_rules! queue_methods {
    ($items:literal, $item:literal) => {
        #[doc = concat!("Number of queued ", $items, ".")]
        pub fn len(&self) -> usize {
            self.queue.len()
        }

        #[doc = concat!("Whether no ", $item, " is queued.")]
        pub fn is_empty(&self) -> bool {
            self.len() == 0
        }

        #[doc = concat!("The ", $items, " dropped because the queue was full.")]
        pub fn dropped(&self) -> u64 {
            self.queue.dropped()
        }

        #[doc = concat!("Sets how many ", $items, " the queue keeps (at least 1); the oldest")]
        /// beyond that are dropped and counted.
        pub fn set_capacity(&mut self, capacity: usize) {
            self.queue.set_capacity(capacity);
        }
    };
}

/// The events of a tokio [`super::Master`] that no call of it waited for
/// (see [`super::Master::events`]), oldest first.
///
/// A [`Stream`]; [`Events::next`] is the same without a stream adapter.
/// It ends (`None`) once the driver stopped and the queued events are
/// taken. At most its capacity of events is kept (default
/// [`super::MASTER_QUEUE_CAPACITY`]); beyond that the oldest are dropped
/// and counted in [`Events::dropped`].
#[derive(Debug)]
pub struct Events {
    pub(super) queue: std::sync::Arc<Queue<MasterEvent>>,
}

impl Events {
    /// The next event; waits for one. `None` once the driver stopped and
    /// every queued event was taken. Cancellation-safe.
    pub async fn next(&mut self) -> Option<MasterEvent> {
        poll_fn(|cx| self.queue.poll_pop(cx)).await
    }

    /// The oldest queued event, without waiting.
    pub fn try_next(&mut self) -> Option<MasterEvent> {
        self.queue.try_pop()
    }

    queue_methods!("events", "event");

    /// Whether the driver stopped (queued events can still be taken).
    pub fn is_closed(&self) -> bool {
        self.queue.is_closed()
    }
}

impl Stream for Events {
    type Item = MasterEvent;

    fn poll_next(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<Option<MasterEvent>> {
        self.queue.poll_pop(cx)
    }
}

/// The PDO `P` as received by a tokio [`super::Master`] (see
/// [`super::Master::pdos`]), oldest first: `Ok(P)` for each frame on its
/// COB-ID, or the length error of a frame with another length than the
/// watched one (its data is not taken).
///
/// A [`Stream`]; [`Pdos::next`] is the same without a stream adapter. It
/// ends once the driver stopped and every queued value was taken. At most
/// its capacity (default [`PDO_QUEUE_CAPACITY`]) is kept; beyond that the
/// oldest are dropped and counted in [`Pdos::dropped`].
#[derive(Debug)]
pub struct Pdos<P> {
    pub(super) can_id: CanId,
    pub(super) queue: std::sync::Arc<Queue<PdoEvent>>,
    pub(super) pdo: PhantomData<fn() -> P>,
}

/// PDOs a [`Pdos`] stream keeps by default.
pub const PDO_QUEUE_CAPACITY: usize = 256;

impl<P: od::Pdo> Pdos<P> {
    /// The next value; waits for one. `None` once the driver stopped and
    /// every queued value was taken. Cancellation-safe.
    pub async fn next(&mut self) -> Option<Result<P, PdoLengthError>> {
        poll_fn(|cx| self.poll_value(cx)).await
    }

    /// The oldest queued value, without waiting.
    pub fn try_next(&mut self) -> Option<Result<P, PdoLengthError>> {
        loop {
            if let Some(value) = decode(self.queue.try_pop()?) {
                return Some(value);
            }
        }
    }

    fn poll_value(&self, cx: &mut Context<'_>) -> Poll<Option<Result<P, PdoLengthError>>> {
        loop {
            match self.queue.poll_pop(cx) {
                Poll::Ready(Some(event)) => {
                    if let Some(value) = decode(event) {
                        return Poll::Ready(Some(value));
                    }
                }
                Poll::Ready(None) => return Poll::Ready(None),
                Poll::Pending => return Poll::Pending,
            }
        }
    }

    /// The identifier the stream receives.
    pub fn can_id(&self) -> CanId {
        self.can_id
    }

    queue_methods!("values", "value");
}

/// The value of a PDO event the driver queued for a [`Pdos`] (only
/// receptions and length errors are queued; others give `None`).
fn decode<P: od::Pdo>(event: PdoEvent) -> Option<Result<P, PdoLengthError>> {
    match event {
        PdoEvent::Received { data, len, .. } => {
            let bytes = data.get(..len).unwrap_or(&data);
            Some(P::decode(bytes))
        }
        PdoEvent::LengthError {
            expected, actual, ..
        } => Some(Err(PdoLengthError { expected, actual })),
        PdoEvent::Timeout { .. } => None,
    }
}

impl<P: od::Pdo> Stream for Pdos<P> {
    type Item = Result<P, PdoLengthError>;

    fn poll_next(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<Option<Self::Item>> {
        self.poll_value(cx)
    }
}
