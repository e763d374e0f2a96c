use super::*;
use crate::CanId;
use crate::cores::testing::{assert_due, data, events, frames, ms, node};

#[test]
fn frame_layouts() {
    assert_eq!(boot_up_frame(node(32)), data(0x720, &[0x00]));
    assert_eq!(
        heartbeat_frame(node(32), NmtState::Operational),
        data(0x720, &[0x05])
    );
    assert_eq!(
        heartbeat_frame(node(1), NmtState::PreOperational),
        data(0x701, &[0x7F])
    );
    assert_eq!(
        parse_heartbeat(&data(0x77F, &[0x04])),
        Some((node(127), NmtState::Stopped))
    );
    assert_eq!(
        parse_heartbeat(&data(0x720, &[0x85])),
        Some((node(32), NmtState::Operational))
    );
    assert_eq!(parse_heartbeat(&data(0x700, &[0x05])), None);
    assert_eq!(parse_heartbeat(&data(0x720, &[])), None);
    assert_eq!(parse_heartbeat(&data(0x720, &[0x05, 0])), None);
    assert_eq!(parse_heartbeat(&data(0x720, &[0x06])), None);
    assert_eq!(parse_heartbeat(&data(0x6A0, &[0x05])), None);
    assert_eq!(
        parse_heartbeat(&Frame::remote(CanId::Standard(0x720), 1).unwrap()),
        None
    );
}

#[test]
fn producer_sends_boot_up_then_periodic_heartbeats() {
    let mut p = HeartbeatProducer::new(node(32), Some(Duration::from_millis(100)));
    assert_eq!(p.poll_timeout(), None);
    assert!(frames(&mut p).is_empty());
    p.start(ms(1000));
    assert_eq!(frames(&mut p), [data(0x720, &[0x00])]);
    assert_due(&mut p, 1100, &[data(0x720, &[0x7F])]);
    assert_eq!(p.poll_timeout(), Some(ms(1200)));
    p.set_state(NmtState::Operational);
    // Handled a little late: the schedule does not drift.
    p.handle_timeout(ms(1203));
    assert_eq!(frames(&mut p), [data(0x720, &[0x05])]);
    assert_eq!(p.poll_timeout(), Some(ms(1300)));
}

#[test]
fn producer_big_time_jump_sends_one_frame() {
    let mut p = HeartbeatProducer::new(node(5), Some(Duration::from_millis(10)));
    p.start(ms(0));
    frames(&mut p);
    p.handle_timeout(ms(60_000));
    assert_eq!(frames(&mut p), [data(0x705, &[0x7F])]);
    assert_eq!(p.poll_timeout(), Some(ms(60_010)));
}

#[test]
fn producer_zero_period_and_period_changes() {
    let mut p = HeartbeatProducer::new(node(5), None);
    p.start(ms(0));
    assert_eq!(p.poll_timeout(), None);
    assert_eq!(frames(&mut p), [data(0x705, &[0x00])]);
    assert!(p.is_running());
    // Enabled later (0x1017 written while running).
    p.set_period(ms(70), Some(Duration::from_millis(20)));
    assert_eq!(p.poll_timeout(), Some(ms(90)));
    p.handle_timeout(ms(90));
    p.stop();
    assert!(!p.is_running());
    assert_eq!(p.poll_timeout(), None);
    assert!(frames(&mut p).is_empty());
    // Not started: a period change schedules nothing.
    p.set_period(ms(100), Some(Duration::from_millis(20)));
    assert_eq!(p.poll_timeout(), None);
    // A period below 1 ms counts as 1 ms.
    p.set_period(ms(100), Some(Duration::from_micros(10)));
    assert_eq!(p.period(), Some(Duration::from_millis(1)));
    assert_eq!(p.poll_timeout(), None);
}

#[test]
fn consumer_times_out_once_after_exactly_the_consumer_time() {
    let mut c = HeartbeatConsumer::new();
    c.monitor(node(32), Some(Duration::from_millis(150)));
    // Supervision starts with the first heartbeat.
    assert_eq!(c.poll_timeout(), None);
    c.handle_timeout(ms(10_000));
    assert!(events(&mut c).is_empty());
    c.handle_frame(ms(10_000), &data(0x720, &[0x05]));
    assert_eq!(
        events(&mut c),
        [HeartbeatEvent::State {
            node: node(32),
            state: NmtState::Operational
        }]
    );
    assert_eq!(c.poll_timeout(), Some(ms(10_150)));
    c.handle_timeout(Instant::from_micros(10_149_999));
    assert!(events(&mut c).is_empty());
    c.handle_timeout(ms(10_150));
    assert_eq!(events(&mut c), [HeartbeatEvent::Timeout { node: node(32) }]);
    assert!(c.is_timed_out(node(32)));
    // Not repeated.
    assert_eq!(c.poll_timeout(), None);
    c.handle_timeout(ms(20_000));
    assert!(events(&mut c).is_empty());
    // Back, same state: only Resumed.
    c.handle_frame(ms(20_000), &data(0x720, &[0x05]));
    assert_eq!(
        events(&mut c),
        [HeartbeatEvent::Resumed {
            node: node(32),
            state: NmtState::Operational
        }]
    );
    assert_eq!(c.poll_timeout(), Some(ms(20_150)));
    // A heartbeat in time pushes the deadline.
    c.handle_frame(ms(20_100), &data(0x720, &[0x05]));
    c.handle_timeout(ms(20_150));
    assert!(events(&mut c).is_empty());
    assert_eq!(c.poll_timeout(), Some(ms(20_250)));
}

#[test]
fn consumer_reports_state_changes_and_every_boot_up() {
    let mut c = HeartbeatConsumer::new();
    c.monitor(node(32), Some(Duration::from_millis(150)));
    let t = ms(0);
    for b in [0x00, 0x7F, 0x7F, 0x00, 0x00, 0x04] {
        c.handle_frame(t, &data(0x720, &[b]));
    }
    let states: Vec<_> = events(&mut c)
        .into_iter()
        .map(|e| match e {
            HeartbeatEvent::State { state, .. } => state,
            other => panic!("{other:?}"),
        })
        .collect();
    use NmtState::*;
    assert_eq!(states, [BootUp, PreOperational, BootUp, BootUp, Stopped]);
    // Unmonitored nodes and unknown states are ignored.
    c.handle_frame(t, &data(0x721, &[0x05]));
    c.handle_frame(t, &data(0x720, &[0x33]));
    assert!(events(&mut c).is_empty());
    assert_eq!(c.state(node(32)), Some(Stopped));
    c.forget(node(32));
    assert_eq!(c.poll_timeout(), None);
    assert!(!c.is_monitored(node(32)));
}

#[test]
fn producer_feeds_consumer() {
    let mut p = HeartbeatProducer::new(node(32), Some(Duration::from_millis(100)));
    let mut c = HeartbeatConsumer::new();
    c.monitor(node(32), Some(Duration::from_millis(150)));
    p.start(ms(0));
    let mut seen = Vec::new();
    for t in (0..=1000).step_by(10) {
        if t == 500 {
            p.set_state(NmtState::Operational);
        }
        if t == 700 {
            // Stopped before the heartbeat due at 700 ms.
            p.stop();
        }
        p.handle_timeout(ms(t));
        c.handle_timeout(ms(t));
        for f in frames(&mut p) {
            c.handle_frame(ms(t), &f);
        }
        seen.extend(events(&mut c).into_iter().map(|e| (t, e)));
    }
    let n = node(32);
    use HeartbeatEvent::*;
    use NmtState::*;
    assert_eq!(
        seen,
        [
            (
                0,
                State {
                    node: n,
                    state: BootUp
                }
            ),
            (
                100,
                State {
                    node: n,
                    state: PreOperational
                }
            ),
            (
                500,
                State {
                    node: n,
                    state: Operational
                }
            ),
            // Last heartbeat at 600 ms + 150 ms consumer time.
            (750, Timeout { node: n }),
        ]
    );
}

#[test]
fn consumer_entries_and_many_timeouts() {
    assert_eq!(
        parse_consumer_entry(0x0020_01F4),
        Some((node(32), Duration::from_millis(500)))
    );
    assert_eq!(parse_consumer_entry(0x0020_0000), None);
    assert_eq!(parse_consumer_entry(0x0080_0010), None);
    assert_eq!(parse_consumer_entry(0x0000_0010), None);
    assert_eq!(
        consumer_entry(node(32), Duration::from_millis(500)),
        0x0020_01F4
    );
    let entries: Vec<u32> = (1..=127u32).map(|n| n << 16 | 100).collect();
    let mut c = HeartbeatConsumer::new();
    c.configure(&entries);
    for n in 1..=127u16 {
        c.handle_frame(ms(0), &data(0x700 + n, &[0x05]));
    }
    events(&mut c);
    c.handle_timeout(ms(100));
    let got = events(&mut c);
    assert_eq!(got.len(), 127);
    assert_eq!(c.dropped_events(), 0);
    assert_eq!(got[0], HeartbeatEvent::Timeout { node: node(1) });
}
