use super::*;
use crate::CanId;

fn frame(id: u16, data: &[u8]) -> Frame {
    Frame::new(CanId::Standard(id), data).unwrap()
}

#[test]
fn broadcast_reaches_every_other_port_in_order() {
    let bus = VirtualBus::new();
    let a = bus.attach();
    let b = bus.attach();
    let c = bus.attach();
    a.transmit(&frame(0x100, &[1]));
    b.transmit(&frame(0x200, &[2]));
    a.transmit(&frame(0x101, &[3]));
    // A sender never gets its own frames back.
    assert_eq!(a.try_recv(), Some(frame(0x200, &[2])));
    assert_eq!(a.try_recv(), None);
    assert_eq!(b.try_recv(), Some(frame(0x100, &[1])));
    assert_eq!(b.try_recv(), Some(frame(0x101, &[3])));
    assert_eq!(b.try_recv(), None);
    // Every port sees the one global order.
    assert_eq!(c.pending(), 3);
    assert_eq!(c.try_recv(), Some(frame(0x100, &[1])));
    assert_eq!(c.try_recv(), Some(frame(0x200, &[2])));
    assert_eq!(c.try_recv(), Some(frame(0x101, &[3])));
    assert_eq!(c.try_recv(), None);
}

#[test]
fn loopback_port_gets_its_own_frames() {
    let bus = VirtualBus::new();
    let a = bus.attach_with_loopback();
    let b = bus.attach();
    assert!(a.loopback() && !b.loopback());
    a.transmit(&frame(0x1, &[]));
    b.transmit(&frame(0x2, &[]));
    assert_eq!(a.try_recv(), Some(frame(0x1, &[])));
    assert_eq!(a.try_recv(), Some(frame(0x2, &[])));
    b.set_loopback(true);
    b.transmit(&frame(0x3, &[]));
    assert_eq!(b.try_recv(), Some(frame(0x1, &[])));
    assert_eq!(b.try_recv(), Some(frame(0x3, &[])));
    a.set_loopback(false);
    a.transmit(&frame(0x4, &[]));
    assert_eq!(a.try_recv(), Some(frame(0x3, &[])));
    assert_eq!(a.try_recv(), None);
}

#[test]
fn overrun_drops_the_oldest_and_counts() {
    let bus = VirtualBus::new().with_queue_capacity(3);
    let tx = bus.attach();
    let rx = bus.attach();
    for i in 0..5u8 {
        tx.transmit(&frame(0x180, &[i]));
    }
    assert_eq!(rx.pending(), 3);
    assert_eq!(rx.overruns(), 2);
    let got: Vec<u8> = std::iter::from_fn(|| rx.try_recv())
        .map(|f| f.data()[0])
        .collect();
    assert_eq!(got, [2, 3, 4]);
    // The sender's queue is untouched.
    assert_eq!((tx.pending(), tx.overruns()), (0, 0));
}

#[test]
fn default_capacity_is_bounded() {
    let bus = VirtualBus::new();
    let tx = bus.attach();
    let rx = bus.attach();
    for i in 0..(DEFAULT_QUEUE_CAPACITY + 10) {
        tx.transmit(&frame(0x180, &(i as u32).to_le_bytes()));
    }
    assert_eq!(rx.pending(), DEFAULT_QUEUE_CAPACITY);
    assert_eq!(rx.overruns(), 10);
    assert_eq!(rx.try_recv(), Some(frame(0x180, &10u32.to_le_bytes())));
}

#[test]
fn dropping_a_port_detaches_it() {
    let bus = VirtualBus::new();
    let a = bus.attach();
    let b = bus.attach();
    assert_eq!(bus.port_count(), 2);
    drop(b);
    assert_eq!(bus.port_count(), 1);
    a.transmit(&frame(0x1, &[]));
    let c = bus.attach();
    // A port attached later does not see earlier frames.
    assert_eq!(c.try_recv(), None);
    assert_eq!(a.bus().port_count(), 2);
}

#[test]
fn recv_times_out_and_wakes_on_a_frame() {
    let bus = VirtualBus::new();
    let mut a = bus.attach();
    let b = bus.attach();
    let start = std::time::Instant::now();
    assert_eq!(a.recv(Duration::from_millis(30)).unwrap(), None);
    let waited = start.elapsed();
    assert!(waited >= Duration::from_millis(30), "{waited:?}");
    assert_eq!(a.recv(Duration::ZERO).unwrap(), None);

    let sender = std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(20));
        b.transmit(&frame(0x701, &[0x05]));
        b
    });
    let start = std::time::Instant::now();
    let got = a.recv(Duration::from_secs(5)).unwrap();
    assert_eq!(got, Some(frame(0x701, &[0x05])));
    assert!(start.elapsed() < Duration::from_secs(4));
    drop(sender.join().unwrap());
}

#[test]
fn stats_count_bits_and_busy_time() {
    let bus = VirtualBus::with_bit_rate(500_000);
    let a = bus.attach();
    let _b = bus.attach();
    // 0x701#05 takes 58 bits, 0x000# 53 (derived in wire.rs's tests).
    a.transmit(&frame(0x701, &[0x05]));
    a.transmit(&frame(0x000, &[]));
    a.transmit(&Frame::remote(CanId::Standard(0x701), 1).unwrap());
    let stats = bus.stats();
    let rtr_bits = u64::from(frame_bits(
        &Frame::remote(CanId::Standard(0x701), 1).unwrap(),
    ));
    assert_eq!(stats.frames, 3);
    assert_eq!(stats.payload_bytes, 1);
    assert_eq!(stats.bits, 58 + 53 + rtr_bits);
    // 2 µs per bit at 500 kbit/s.
    assert_eq!(stats.busy, Duration::from_micros(2 * stats.bits));
    let load = stats.load(Duration::from_micros(4 * stats.bits));
    assert!((load - 0.5).abs() < 1e-9);

    let plain = VirtualBus::new();
    plain.attach().transmit(&frame(0x1, &[1, 2]));
    assert_eq!(
        plain.stats(),
        BusStats {
            frames: 1,
            bits: 0,
            busy: Duration::ZERO,
            payload_bytes: 2
        }
    );
}

#[test]
fn busy_time_is_exact() {
    assert_eq!(busy_time(1, 3), Duration::from_nanos(333_333_333));
    assert_eq!(busy_time(250_000, 125_000), Duration::from_secs(2));
    assert_eq!(busy_time(u64::MAX, 1), Duration::from_secs(u64::MAX));
}

#[cfg(feature = "tokio")]
mod tokio_tests {
    use super::*;
    use crate::transport::AsyncBus;

    #[::tokio::test]
    async fn async_recv_wakes_and_keeps_order() {
        let bus = VirtualBus::new();
        let mut a = bus.attach();
        let mut b = bus.attach();
        let task = ::tokio::spawn(async move {
            let first = AsyncBus::recv(&mut a).await.unwrap();
            let second = AsyncBus::recv(&mut a).await.unwrap();
            (first, second)
        });
        // One thread: the task runs up to its first (pending) receive.
        ::tokio::task::yield_now().await;
        assert!(!task.is_finished());
        AsyncBus::send(&mut b, &frame(0x1, &[1])).await.unwrap();
        AsyncBus::send(&mut b, &frame(0x2, &[2])).await.unwrap();
        let (first, second) = task.await.unwrap();
        assert_eq!((first, second), (frame(0x1, &[1]), frame(0x2, &[2])));
    }

    #[::tokio::test(start_paused = true)]
    async fn async_recv_is_cancel_safe() {
        let bus = VirtualBus::new();
        let mut a = bus.attach();
        let b = bus.attach();
        // A timed-out recv loses nothing.
        let timed_out =
            ::tokio::time::timeout(Duration::from_millis(50), AsyncBus::recv(&mut a)).await;
        assert!(timed_out.is_err());
        // A recv that was waiting when a frame came, then dropped before it
        // was polled again, does not take the frame.
        {
            let fut = AsyncBus::recv(&mut a);
            let mut fut = core::pin::pin!(fut);
            assert!(poll_once(fut.as_mut()).await.is_none());
            b.transmit(&frame(0x3, &[3]));
        }
        assert_eq!(AsyncBus::recv(&mut a).await.unwrap(), frame(0x3, &[3]));
        assert_eq!(a.try_recv(), None);
    }

    /// Polls a future once.
    async fn poll_once<F: Future + Unpin>(fut: F) -> Option<F::Output> {
        let mut fut = fut;
        core::future::poll_fn(|cx| {
            core::task::Poll::Ready(match core::pin::Pin::new(&mut fut).poll(cx) {
                core::task::Poll::Ready(v) => Some(v),
                core::task::Poll::Pending => None,
            })
        })
        .await
    }

    #[::tokio::test(start_paused = true)]
    async fn select_between_recv_and_sleep_loses_nothing() {
        let bus = VirtualBus::new();
        let mut a = bus.attach();
        let b = bus.attach();
        let mut got = Vec::new();
        let mut sent = 0u8;
        while got.len() < 20 {
            if sent < 20 {
                b.transmit(&frame(0x180, &[sent]));
                sent += 1;
            }
            ::tokio::select! {
                r = AsyncBus::recv(&mut a) => got.push(r.unwrap().data()[0]),
                _ = ::tokio::time::sleep(Duration::from_millis(1)) => {}
            }
        }
        assert_eq!(got, (0..20).collect::<Vec<u8>>());
    }
}
