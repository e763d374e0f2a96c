//! Property tests of the TIME service (`time_stamp`): civil date and time
//! ↔ `TimeOfDay` ↔ bytes round trips over the whole range, the decoder on
//! arbitrary bytes, and the consumer and the master on arbitrary frames.

use core::time::Duration;

use eds2rust_runtime::master::{Master, MasterEvent};
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::time_stamp::{
    DateTime, MS_PER_DAY, TimeConsumer, TimeError, TimeEvent, TimeOfDay, TimeProducer,
    days_in_month, time_frame,
};
use eds2rust_runtime::{CanId, Frame, Instant, Service, TimeDifference};
use proptest::prelude::*;

fn time() -> impl Strategy<Value = TimeOfDay> {
    prop_oneof![
        (any::<u16>(), 0..MS_PER_DAY),
        // The edges of a day and of the range.
        (
            prop_oneof![Just(0u16), Just(u16::MAX), any::<u16>()],
            prop_oneof![Just(0u32), Just(MS_PER_DAY - 1)]
        ),
    ]
    .prop_map(|(days, ms)| TimeOfDay::new(days, ms).unwrap())
}

/// A valid civil date and time between 1984 and 2163.
fn date_time() -> impl Strategy<Value = DateTime> {
    (
        1984u16..=2163,
        1u8..=12,
        1u8..=31,
        0u8..24,
        0u8..60,
        0u8..60,
        0u16..1000,
    )
        .prop_map(|(year, month, day, hour, minute, second, ms)| {
            let day = day.min(days_in_month(year, month));
            DateTime::new(year, month, day, hour, minute, second, ms)
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 4096, ..ProptestConfig::default() })]

    #[test]
    fn bytes_round_trip(t in time()) {
        let bytes = t.encode();
        // Reserved bits are always sent as 0.
        prop_assert_eq!(bytes[3] & 0xF0, 0);
        prop_assert_eq!(TimeOfDay::decode(&bytes), Ok(t));
        prop_assert_eq!(TimeOfDay::from_raw48(t.to_raw48()), Ok(t));
        // The raw form is the bytes read as one little-endian integer.
        let mut raw = [0u8; 8];
        raw[..6].copy_from_slice(&bytes);
        prop_assert_eq!(u64::from_le_bytes(raw), t.to_raw48());
        prop_assert_eq!(TimeOfDay::from_epoch_millis(t.epoch_millis()), Ok(t));
        prop_assert_eq!(TimeOfDay::from_unix_millis(t.unix_millis()), Ok(t));
        let d = TimeDifference::new(t.days(), t.millis()).unwrap();
        prop_assert_eq!(d.encode(), bytes);
        prop_assert_eq!(TimeDifference::from_duration(d.to_duration()), Ok(d));
    }

    #[test]
    fn civil_round_trip(t in time(), dt in date_time()) {
        let c = t.to_civil();
        prop_assert!(c.is_valid(), "{c:?}");
        prop_assert_eq!(TimeOfDay::from_civil(c), Ok(t));
        prop_assert_eq!(t.to_string(), c.to_string());
        match TimeOfDay::from_civil(dt) {
            Ok(t) => prop_assert_eq!(t.to_civil(), dt),
            // Only after 2163-06-06.
            Err(e) => {
                let beyond = matches!(e, TimeError::OutOfRange { days } if days > 65_535);
                prop_assert!(beyond, "{:?}", e);
                prop_assert!(dt > DateTime::new(2163, 6, 6, 23, 59, 59, 999));
            }
        }
    }

    #[test]
    fn order_and_differences_agree(a in time(), b in time()) {
        prop_assert_eq!(a.cmp(&b), a.epoch_millis().cmp(&b.epoch_millis()));
        prop_assert_eq!(a.cmp(&b), a.to_civil().cmp(&b.to_civil()));
        let (early, late) = if a <= b { (a, b) } else { (b, a) };
        let d = late.checked_difference(early).unwrap();
        prop_assert_eq!(early.checked_add(d), Some(late));
        prop_assert_eq!(late.checked_sub(d), Some(early));
    }

    #[test]
    fn decoding_any_bytes_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..=10)) {
        match TimeOfDay::decode(&bytes) {
            // Whatever decodes is the encoding of its value.
            Ok(t) => prop_assert_eq!(&t.encode()[..], &bytes[..]),
            Err(TimeError::Length(n)) => {
                prop_assert_eq!(n, bytes.len());
                prop_assert_ne!(n, 6);
            }
            Err(TimeError::ReservedBits(r)) => prop_assert_eq!(r, bytes[3] >> 4),
            Err(TimeError::Millis(ms)) => prop_assert!(ms >= MS_PER_DAY),
            Err(e) => prop_assert!(false, "unexpected {e:?}"),
        }
    }

    #[test]
    fn consumer_and_master_on_any_frames(
        frames in proptest::collection::vec(
            (prop_oneof![Just(0x100u16), any::<u16>()], any::<bool>(), any::<bool>(),
             proptest::collection::vec(any::<u8>(), 0..=8)),
            0..32)
    ) {
        let mut consumer = TimeConsumer::new();
        let mut master = Master::new(NodeId::new(1).unwrap(), None);
        master.start(Instant::ZERO);
        while master.poll_transmit().is_some() {}
        for (i, (id, extended, remote, data)) in frames.iter().enumerate() {
            let id = if *extended { CanId::Extended(u32::from(*id)) } else { CanId::Standard(id & 0x7FF) };
            let frame = if *remote {
                Frame::remote(id, 6).unwrap()
            } else {
                Frame::new(id, data).unwrap()
            };
            let now = Instant::from_millis(i as u64);
            consumer.handle_frame(now, &frame);
            master.handle_frame(now, &frame);
            let ours = consumer.poll_event();
            prop_assert!(consumer.poll_event().is_none());
            let is_time = !frame.is_remote() && frame.id() == CanId::Standard(0x100);
            prop_assert_eq!(ours.is_some(), is_time);
            let time_events: Vec<TimeEvent> = core::iter::from_fn(|| master.poll_event())
                .filter_map(|e| match e { MasterEvent::Time(t) => Some(t), _ => None })
                .collect();
            prop_assert_eq!(time_events, ours.into_iter().collect::<Vec<_>>());
            if let Some(TimeEvent::Time { time, received }) = ours {
                prop_assert_eq!(received, now);
                prop_assert_eq!(time_frame(CanId::Standard(0x100), time), frame);
            }
        }
    }

    #[test]
    fn producer_frames_decode_to_the_extrapolated_time(
        t in time(),
        steps in proptest::collection::vec(0u64..5_000_000, 1..16)
    ) {
        let mut producer = TimeProducer::new(Some(Duration::from_millis(100)));
        producer.set_time(Instant::ZERO, t);
        producer.start(Instant::ZERO);
        let mut consumer = TimeConsumer::new();
        let mut now = Instant::ZERO;
        for step in steps {
            now += Duration::from_micros(step);
            if producer.poll_timeout().is_some_and(|due| due <= now) {
                producer.handle_timeout(now);
            }
            while let Some(frame) = producer.poll_transmit() {
                consumer.handle_frame(now, &frame);
            }
            while let Some(event) = consumer.poll_event() {
                let TimeEvent::Time { time, .. } = event else {
                    return Err(TestCaseError::fail(format!("{event:?}")));
                };
                // Whole milliseconds since the reference, truncated.
                let expected = t.epoch_millis() + now.as_micros() / 1000;
                prop_assert_eq!(time.epoch_millis(), expected);
            }
        }
        // Sends stop after 2163-06-06; none were ever malformed.
        prop_assert!(producer.skipped() == 0 || producer.time_at(now).is_none());
    }
}
