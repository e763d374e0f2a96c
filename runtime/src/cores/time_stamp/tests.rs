//! Frames worked out by hand from the CiA 301 layout: bytes 0..=3 the
//! milliseconds after midnight (little endian, top 4 bits reserved),
//! bytes 4..=5 the days since 1984-01-01 (little endian).

use std::string::ToString;

use super::*;
use crate::cores::testing::{events, frames, ms};
use crate::{CanId, Frame, Service};

fn civil(y: u16, mo: u8, d: u8, h: u8, mi: u8, s: u8, ms: u16) -> TimeOfDay {
    TimeOfDay::from_civil(DateTime::new(y, mo, d, h, mi, s, ms)).unwrap()
}

/// Encodes, decodes back and checks the civil round trip.
fn check(t: TimeOfDay, bytes: [u8; 6]) {
    assert_eq!(t.encode(), bytes, "{t}");
    assert_eq!(TimeOfDay::decode(&bytes), Ok(t));
    assert_eq!(TimeOfDay::from_civil(t.to_civil()), Ok(t));
}

#[test]
fn the_epoch_is_all_zero() {
    // 1984-01-01 00:00:00.000: day 0, 0 ms.
    let t = civil(1984, 1, 1, 0, 0, 0, 0);
    assert_eq!(t, TimeOfDay::EPOCH);
    check(t, [0; 6]);
    assert_eq!(t.to_string(), "1984-01-01T00:00:00.000Z");
}

#[test]
fn a_time_of_day_in_2026() {
    // ms = 12*3_600_000 + 34*60_000 + 56*1000 + 789
    //    = 43_200_000 + 2_040_000 + 56_000 + 789 = 45_296_789 = 0x02B3_2C95
    //    (0x02B3_0000 = 45_285_376, remainder 11_413 = 0x2C95)
    // days: 1984..=2025 are 42 years with 11 leap days (1984, 88, 92, 96,
    //    2000, 04, 08, 12, 16, 20, 24): 42*365 + 11 = 15_341; 2026-01-01 to
    //    2026-12-02 is 334 + 1 = 335 days (Jan..Nov = 334): 15_676 = 0x3D3C.
    let t = civil(2026, 12, 2, 12, 34, 56, 789);
    assert_eq!((t.days(), t.millis()), (15_676, 45_296_789));
    check(t, [0x95, 0x2C, 0xB3, 0x02, 0x3C, 0x3D]);
    assert_eq!(t.to_string(), "2026-12-02T12:34:56.789Z");
    assert_eq!(t.to_raw48(), 0x3D3C_02B3_2C95);
    assert_eq!(TimeOfDay::from_raw48(0x3D3C_02B3_2C95), Ok(t));
}

#[test]
fn the_last_millisecond_of_a_day() {
    // 23:59:59.999 = 86_400_000 - 1 = 0x0526_5C00 - 1 = 0x0526_5BFF.
    let t = civil(1984, 1, 1, 23, 59, 59, 999);
    check(t, [0xFF, 0x5B, 0x26, 0x05, 0x00, 0x00]);
    // One millisecond later: the next day, 0 ms.
    let next = TimeDifference::new(0, 1).unwrap();
    assert_eq!(t.checked_add(next), Some(civil(1984, 1, 2, 0, 0, 0, 0)));
    check(civil(1984, 1, 2, 0, 0, 0, 0), [0, 0, 0, 0, 0x01, 0x00]);
}

#[test]
fn leap_days() {
    // 2000-02-29: 1984..=1999 are 16 years with 4 leap days (1984, 88,
    // 92, 96): 16*365 + 4 = 5_844; plus 31 (January) + 28 = 5_903 = 0x170F.
    // 06:00:00.000 = 21_600_000 ms = 0x0149_9700.
    check(
        civil(2000, 2, 29, 6, 0, 0, 0),
        [0x00, 0x97, 0x49, 0x01, 0x0F, 0x17],
    );
    // 2024-02-29: 1984..=2023 are 40 years with 10 leap days: 14_610;
    // plus 59 = 14_669 = 0x394D; the next day is 2024-03-01.
    check(civil(2024, 2, 29, 0, 0, 0, 0), [0, 0, 0, 0, 0x4D, 0x39]);
    check(civil(2024, 3, 1, 0, 0, 0, 0), [0, 0, 0, 0, 0x4E, 0x39]);
    check(civil(2024, 2, 28, 0, 0, 0, 0), [0, 0, 0, 0, 0x4C, 0x39]);
    // 2000 is a leap year (divisible by 400), 2100 and 1900 are not.
    assert!(DateTime::date(2000, 2, 29).is_valid());
    for year in [1900, 2023, 2100] {
        let dt = DateTime::date(year, 2, 29);
        assert_eq!(TimeOfDay::from_civil(dt), Err(TimeError::InvalidCivil(dt)));
    }
}

#[test]
fn the_last_day_is_2163_06_06() {
    // 1984..=2162 are 179 years; leap years 1984, 1988, ..., 2160 are 45,
    // less 2100: 44. 2163-01-01 is day 179*365 + 44 = 65_379, and
    // 65_535 - 65_379 = 156 = 151 (January to May) + 5: June 6.
    let last = civil(2163, 6, 6, 23, 59, 59, 999);
    assert_eq!(last, TimeOfDay::MAX);
    check(last, [0xFF, 0x5B, 0x26, 0x05, 0xFF, 0xFF]);
    assert_eq!(last.to_string(), "2163-06-06T23:59:59.999Z");
    assert_eq!(
        TimeOfDay::from_civil(DateTime::date(2163, 6, 7)),
        Err(TimeError::OutOfRange { days: 65_536 })
    );
    assert_eq!(
        TimeOfDay::from_civil(DateTime::new(1983, 12, 31, 23, 59, 59, 999)),
        Err(TimeError::OutOfRange { days: -1 })
    );
    assert_eq!(last.checked_add(TimeDifference::new(0, 1).unwrap()), None);
    assert_eq!(
        TimeOfDay::EPOCH.checked_sub(TimeDifference::new(0, 1).unwrap()),
        None
    );
}

#[test]
fn malformed_bytes_are_rejected() {
    // 86_400_000 ms = 0x0526_5C00: one past the last millisecond.
    assert_eq!(
        TimeOfDay::decode(&[0x00, 0x5C, 0x26, 0x05, 0, 0]),
        Err(TimeError::Millis(86_400_000))
    );
    // The largest 28-bit value 0x0FFF_FFFF is no time either.
    assert_eq!(
        TimeOfDay::decode(&[0xFF, 0xFF, 0xFF, 0x0F, 0, 0]),
        Err(TimeError::Millis(0x0FFF_FFFF))
    );
    // Reserved bits 28..31 (the top nibble of byte 3).
    assert_eq!(
        TimeOfDay::decode(&[0, 0, 0, 0x10, 0, 0]),
        Err(TimeError::ReservedBits(1))
    );
    assert_eq!(
        TimeOfDay::decode(&[0, 0, 0, 0xF0, 0, 0]),
        Err(TimeError::ReservedBits(0xF))
    );
    for len in [0, 1, 5, 7, 8] {
        assert_eq!(
            TimeOfDay::decode(&[0; 8][..len]),
            Err(TimeError::Length(len))
        );
    }
    assert_eq!(
        TimeOfDay::new(0, 86_400_000),
        Err(TimeError::Millis(86_400_000))
    );
    assert_eq!(
        TimeOfDay::from_raw48(1 << 48),
        Err(TimeError::Raw48(1 << 48))
    );
    assert_eq!(
        TimeOfDay::from_raw48(0x0000_0526_5C00),
        Err(TimeError::Millis(86_400_000))
    );
    // Errors say what is wrong.
    assert_eq!(
        TimeError::Length(5).to_string(),
        "5 data bytes; TIME_OF_DAY and TIME_DIFFERENCE have exactly 6"
    );
    assert!(
        TimeError::ReservedBits(1)
            .to_string()
            .contains("reserved bits 28 to 31")
    );
    assert!(
        TimeError::OutOfRange { days: -1 }
            .to_string()
            .contains("2163-06-06")
    );
}

#[test]
fn invalid_civil_fields_are_rejected() {
    for dt in [
        DateTime::date(2026, 0, 1),
        DateTime::date(2026, 13, 1),
        DateTime::date(2026, 4, 31),
        DateTime::date(2026, 1, 0),
        DateTime::new(2026, 1, 1, 24, 0, 0, 0),
        DateTime::new(2026, 1, 1, 0, 60, 0, 0),
        // No leap seconds.
        DateTime::new(2016, 12, 31, 23, 59, 60, 0),
        DateTime::new(2026, 1, 1, 0, 0, 0, 1000),
    ] {
        assert_eq!(TimeOfDay::from_civil(dt), Err(TimeError::InvalidCivil(dt)));
    }
    assert_eq!(
        TimeError::InvalidCivil(DateTime::date(2023, 2, 29)).to_string(),
        "2023-02-29T00:00:00.000Z is not a valid UTC date and time"
    );
}

#[test]
fn every_day_follows_the_previous_one() {
    // The whole range against the calendar rules, one day at a time.
    let mut expected = DateTime::date(1984, 1, 1);
    for days in 0..=u16::MAX {
        let t = TimeOfDay::new(days, 0).unwrap();
        assert_eq!(t.to_civil(), expected, "day {days}");
        assert_eq!(TimeOfDay::from_civil(expected), Ok(t));
        expected.day += 1;
        if expected.day > days_in_month(expected.year, expected.month) {
            expected.day = 1;
            expected.month += 1;
            if expected.month > 12 {
                expected.month = 1;
                expected.year += 1;
            }
        }
    }
    assert_eq!(expected, DateTime::date(2163, 6, 7));
    // The Unix epoch and far-away days through the same arithmetic.
    assert_eq!(days_from_civil(1970, 1, 1), 0);
    assert_eq!(days_from_civil(1984, 1, 1), i64::from(UNIX_DAYS_AT_EPOCH));
    assert_eq!(UNIX_DAYS_AT_EPOCH, 5113);
    assert_eq!(days_from_civil(1969, 12, 31), -1);
    assert_eq!(civil_from_days(-1), (1969, 12, 31));
    assert_eq!(days_from_civil(0, 3, 1), -719_468);
    assert_eq!(civil_from_days(-719_468), (0, 3, 1));
}

#[test]
fn unix_time() {
    // 1_486_236_238 s after 1970 (python-canopen's test value):
    // minus 441_763_200 s (5_113 days) = 1_044_473_038 s = 12_088 days
    // (1_044_403_200 s) + 69_838 s; 69_838_000 ms = 0x0429_A4B0,
    // 12_088 = 0x2F38. 69_838 s = 19:23:58.
    let t = TimeOfDay::from_unix_millis(1_486_236_238_000).unwrap();
    assert_eq!(t.encode(), [0xB0, 0xA4, 0x29, 0x04, 0x38, 0x2F]);
    assert_eq!(t.to_string(), "2017-02-04T19:23:58.000Z");
    assert_eq!(t.unix_millis(), 1_486_236_238_000);
    assert_eq!(TimeOfDay::EPOCH.unix_millis(), 441_763_200_000);
    assert_eq!(
        TimeOfDay::from_unix_millis(441_763_199_999),
        Err(TimeError::OutOfRange { days: -1 })
    );
    assert_eq!(
        TimeOfDay::from_unix_millis(-1),
        Err(TimeError::OutOfRange { days: -5114 })
    );
    assert_eq!(
        TimeOfDay::from_unix_millis(i64::MIN),
        Err(TimeError::OutOfRange {
            days: (i128::from(i64::MIN) - 441_763_200_000).div_euclid(86_400_000) as i64
        })
    );
    assert!(matches!(
        TimeOfDay::from_unix_millis(i64::MAX),
        Err(TimeError::OutOfRange { .. })
    ));
}

#[test]
fn system_time() {
    use std::time::{Duration as StdDuration, SystemTime, UNIX_EPOCH};
    let st = UNIX_EPOCH + StdDuration::new(1_486_236_238, 999_999);
    let t = TimeOfDay::try_from(st).unwrap();
    // The sub-millisecond part is truncated.
    assert_eq!(t.unix_millis(), 1_486_236_238_000);
    assert_eq!(
        t.to_system_time(),
        Some(UNIX_EPOCH + StdDuration::from_secs(1_486_236_238))
    );
    assert_eq!(
        TimeOfDay::from_system_time(UNIX_EPOCH),
        Err(TimeError::OutOfRange { days: -5113 })
    );
    let before = UNIX_EPOCH.checked_sub(StdDuration::from_nanos(1)).unwrap();
    assert_eq!(
        TimeOfDay::from_system_time(before),
        Err(TimeError::OutOfRange { days: -5114 })
    );
    assert!(TimeOfDay::MAX.to_system_time().is_some());
    assert!(TimeOfDay::from_system_time(SystemTime::now()).is_ok());
}

#[test]
fn time_difference() {
    // 1 day 02:03:04.005: 7_200_000 + 180_000 + 4_005 = 7_384_005 ms
    // = 0x0070_ABC5 (0x70 * 65_536 = 7_340_032, remainder 43_973 = 0xABC5).
    let d = TimeDifference::new(1, 7_384_005).unwrap();
    assert_eq!(d.encode(), [0xC5, 0xAB, 0x70, 0x00, 0x01, 0x00]);
    assert_eq!(TimeDifference::decode(&d.encode()), Ok(d));
    assert_eq!(d.to_string(), "P1DT2H3M4.005S");
    assert_eq!(TimeDifference::ZERO.to_string(), "P0DT0H0M0.000S");
    assert_eq!(d.total_millis(), 86_400_000 + 7_384_005);
    assert_eq!(
        TimeDifference::try_from(Duration::from_micros(93_784_005_999)),
        Ok(d)
    );
    assert_eq!(Duration::from(d), Duration::from_millis(93_784_005));
    assert_eq!(TimeDifference::from_raw48(d.to_raw48()), Ok(d));
    assert_eq!(
        TimeDifference::from_millis(TimeDifference::MAX.total_millis() + 1),
        Err(TimeError::OutOfRange { days: 65_536 })
    );
    assert_eq!(
        TimeDifference::from_duration(Duration::MAX),
        Err(TimeError::OutOfRange {
            days: (u64::MAX / 86_400) as i64
        })
    );
    assert_eq!(
        TimeDifference::decode(&[0x00, 0x5C, 0x26, 0x05, 0, 0]),
        Err(TimeError::Millis(86_400_000))
    );
    let a = civil(2024, 2, 28, 12, 0, 0, 0);
    let b = a.checked_add(d).unwrap();
    // 2024 is a leap year: the day after 02-28 is 02-29.
    assert_eq!(b, civil(2024, 2, 29, 14, 3, 4, 5));
    assert_eq!(b.checked_difference(a), Some(d));
    assert_eq!(a.checked_difference(b), None);
    assert_eq!(b.checked_sub(d), Some(a));
}

#[test]
fn cob_id_object() {
    let c = TimeCobId::from_raw(0x8000_0100).unwrap();
    assert_eq!(
        c,
        TimeCobId {
            consume: true,
            produce: false,
            id: CanId::Standard(0x100)
        }
    );
    assert_eq!(c.to_raw(), 0x8000_0100);
    let p = TimeCobId::from_raw(0x4000_0100).unwrap();
    assert!(p.produce && !p.consume);
    let x = TimeCobId::from_raw(0xE000_1234).unwrap();
    assert_eq!(x.id, CanId::Extended(0x1234));
    assert!(x.produce && x.consume);
    assert_eq!(x.to_raw(), 0xE000_1234);
    assert_eq!(
        TimeCobId::from_raw(0x0000_0800),
        Err(TimeConfigError::CobId(0x800))
    );
    assert_eq!(TimeCobId::default().to_raw(), 0x100);
    assert!(
        TimeConfigError::CobId(0x800)
            .to_string()
            .contains("0x00000800")
    );
}

#[test]
fn producer_sends_given_and_periodic_times() {
    let t = civil(2026, 12, 2, 12, 34, 56, 789);
    let mut p = TimeProducer::new(Some(Duration::from_secs(1)));
    p.send(TimeOfDay::EPOCH);
    p.send(t);
    // The newer time replaces the one not yet polled.
    assert_eq!(
        frames(&mut p),
        [Frame::standard(
            0x100,
            [0x95, 0x2C, 0xB3, 0x02, 0x3C, 0x3D, 0, 0],
            6
        )]
    );
    assert_eq!(p.poll_timeout(), None);
    // Started without a reference time: the periodic TIME is skipped.
    p.start(ms(1000));
    assert_eq!(p.poll_timeout(), Some(ms(1000)));
    p.handle_timeout(ms(1000));
    assert!(frames(&mut p).is_empty());
    assert_eq!(p.skipped(), 1);
    assert_eq!(p.poll_timeout(), Some(ms(2000)));
    // At 1500 ms of the monotonic clock it is t; at 2000 ms t + 500 ms.
    p.set_time(ms(1500), t);
    p.handle_timeout(ms(2000));
    let sent = frames(&mut p);
    assert_eq!(sent.len(), 1);
    assert_eq!(sent[0].to_string(), "100#892EB3023C3D");
    assert_eq!(
        TimeOfDay::decode(sent[0].data()),
        Ok(civil(2026, 12, 2, 12, 34, 57, 289))
    );
    // A clock jump gives one frame.
    p.handle_timeout(ms(60_000));
    assert_eq!(frames(&mut p).len(), 1);
    assert_eq!(p.poll_timeout(), Some(ms(61_000)));
    assert_eq!(p.send_now(ms(1500)), Some(t));
    p.stop();
    assert!(frames(&mut p).is_empty());
    assert_eq!(p.poll_timeout(), None);
    // After 2163-06-06 nothing is sent.
    p.set_time(ms(0), TimeOfDay::MAX);
    assert_eq!(p.send_now(ms(1)), None);
}

#[test]
fn producer_on_a_29_bit_identifier() {
    let mut p = TimeProducer::with_id(CanId::Extended(0x1234_5678), None).unwrap();
    p.send(TimeOfDay::EPOCH);
    assert_eq!(
        frames(&mut p),
        [Frame::new(CanId::Extended(0x1234_5678), &[0; 6]).unwrap()]
    );
    p.start(ms(0));
    assert_eq!(p.poll_timeout(), None);
    assert_eq!(
        TimeProducer::with_id(CanId::Standard(0x800), None).err(),
        Some(TimeConfigError::Id(CanId::Standard(0x800)))
    );
    assert_eq!(
        TimeConsumer::with_id(CanId::Extended(0x2000_0000)).err(),
        Some(TimeConfigError::Id(CanId::Extended(0x2000_0000)))
    );
}

#[test]
fn consumer_decodes_and_reports_malformed_frames() {
    let mut c = TimeConsumer::new();
    let good = Frame::new(
        CanId::Standard(0x100),
        &[0x95, 0x2C, 0xB3, 0x02, 0x3C, 0x3D],
    )
    .unwrap();
    let short = Frame::new(CanId::Standard(0x100), &[0x95, 0x2C]).unwrap();
    let long = Frame::new(CanId::Standard(0x100), &[0; 8]).unwrap();
    c.handle_frame(ms(5), &good);
    c.handle_frame(ms(6), &short);
    c.handle_frame(ms(7), &long);
    // Not TIME frames: other identifiers, the 29-bit 0x100, remote frames.
    c.handle_frame(ms(8), &Frame::new(CanId::Standard(0x101), &[0; 6]).unwrap());
    c.handle_frame(ms(8), &Frame::new(CanId::Extended(0x100), &[0; 6]).unwrap());
    c.handle_frame(ms(8), &Frame::remote(CanId::Standard(0x100), 6).unwrap());
    let t = civil(2026, 12, 2, 12, 34, 56, 789);
    assert_eq!(
        events(&mut c),
        [
            TimeEvent::Time {
                time: t,
                received: ms(5)
            },
            TimeEvent::Malformed {
                frame: short,
                error: TimeError::Length(2)
            },
            TimeEvent::Malformed {
                frame: long,
                error: TimeError::Length(8)
            },
        ]
    );
    assert_eq!(c.last(), Some((ms(5), t)));
    assert_eq!(
        c.time_at(ms(1005)),
        Some(civil(2026, 12, 2, 12, 34, 57, 789))
    );
    assert_eq!(
        TimeEvent::Malformed {
            frame: short,
            error: TimeError::Length(2)
        }
        .to_string(),
        "malformed TIME 100#952C: 2 data bytes; TIME_OF_DAY and TIME_DIFFERENCE have exactly 6"
    );
    // A 29-bit consumer.
    let mut x = TimeConsumer::with_id(CanId::Extended(0x100)).unwrap();
    x.handle_frame(ms(1), &good);
    x.handle_frame(ms(2), &Frame::new(CanId::Extended(0x100), &[0; 6]).unwrap());
    assert_eq!(
        events(&mut x),
        [TimeEvent::Time {
            time: TimeOfDay::EPOCH,
            received: ms(2)
        }]
    );
    // A full queue drops the oldest.
    for i in 0..CONSUMER_EVENTS as u64 + 3 {
        c.handle_frame(ms(i), &good);
    }
    assert_eq!(events(&mut c).len(), CONSUMER_EVENTS);
    assert_eq!(c.dropped_events(), 3);
}
