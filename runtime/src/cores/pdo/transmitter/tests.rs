use super::*;
use crate::CanId;
use crate::cores::pdo::test_pdos::Command;
use crate::cores::testing::{assert_due, data, ms};
use crate::od::NodeId;

fn us(n: u64) -> Instant {
    Instant::from_micros(n)
}

fn sync() -> Frame {
    data(0x080, &[])
}

fn sync_with(counter: u8) -> Frame {
    data(0x080, &[counter])
}

fn frames(t: &mut PdoTransmitter) -> Vec<Frame> {
    core::iter::from_fn(|| t.poll_transmit()).collect()
}

fn cfg(cob_id: u32, transmission_type: u8) -> TransmitterConfig {
    TransmitterConfig::new(
        PdoCobId(cob_id),
        TransmissionType::from_raw(transmission_type),
    )
}

fn transmitter(cob_id: u32, transmission_type: u8) -> PdoTransmitter {
    PdoTransmitter::new(cfg(cob_id, transmission_type)).unwrap()
}

/// Feeds `syncs` and returns, per SYNC, the frames it triggered.
fn run_syncs(t: &mut PdoTransmitter, syncs: &[Frame]) -> Vec<Vec<Frame>> {
    syncs
        .iter()
        .enumerate()
        .map(|(i, s)| {
            t.handle_frame(ms(i as u64), s);
            frames(t)
        })
        .collect()
}

#[test]
fn cyclic_type_sends_at_every_nth_sync() {
    let mut t = transmitter(0x220, 3);
    t.set_data(ms(0), &[0x11, 0x22]).unwrap();
    assert!(
        frames(&mut t).is_empty(),
        "synchronous: nothing before a SYNC"
    );
    let sent = run_syncs(&mut t, &[sync(); 9]);
    let expected: Vec<Vec<Frame>> = (1..=9)
        .map(|n| {
            if n % 3 == 0 {
                vec![data(0x220, &[0x11, 0x22])]
            } else {
                vec![]
            }
        })
        .collect();
    assert_eq!(sent, expected);
    assert_eq!(t.poll_timeout(), None);
}

#[test]
fn cyclic_type_1_sends_the_current_data_at_every_sync() {
    let mut t = transmitter(0x220, 1);
    // Nothing before the first data.
    t.handle_frame(ms(0), &sync());
    assert!(frames(&mut t).is_empty());
    t.set_data(ms(1), &[1]).unwrap();
    t.handle_frame(ms(2), &sync());
    assert_eq!(frames(&mut t), [data(0x220, &[1])]);
    // Unchanged data is sent again; new data replaces it.
    t.handle_frame(ms(3), &sync());
    assert_eq!(frames(&mut t), [data(0x220, &[1])]);
    t.set_data(ms(4), &[2, 3]).unwrap();
    t.set_data(ms(4), &[4, 5]).unwrap();
    assert!(frames(&mut t).is_empty());
    t.handle_frame(ms(5), &sync_with(7));
    assert_eq!(frames(&mut t), [data(0x220, &[4, 5])]);
}

#[test]
fn acyclic_type_0_sends_once_at_the_sync_after_a_change() {
    let mut t = transmitter(0x301, 0);
    t.set_data(ms(0), &[0xAA]).unwrap();
    assert!(frames(&mut t).is_empty());
    let sent = run_syncs(&mut t, &[sync(), sync(), sync()]);
    assert_eq!(sent, [vec![data(0x301, &[0xAA])], vec![], vec![]]);
    // Two changes between SYNCs: one frame with the latest data.
    t.set_data(ms(10), &[0xBB]).unwrap();
    t.set_data(ms(11), &[0xCC, 0xDD]).unwrap();
    t.handle_frame(ms(12), &sync_with(1));
    assert_eq!(frames(&mut t), [data(0x301, &[0xCC, 0xDD])]);
    t.handle_frame(ms(13), &sync_with(2));
    assert!(frames(&mut t).is_empty());
    // Setting the same value again is still an event.
    t.set_data(ms(14), &[0xCC, 0xDD]).unwrap();
    t.handle_frame(ms(15), &sync_with(3));
    assert_eq!(frames(&mut t), [data(0x301, &[0xCC, 0xDD])]);
}

#[test]
fn sync_start_value_picks_the_first_counted_sync() {
    let mut config = cfg(0x220, 2);
    config.sync_start = 3;
    let mut t = PdoTransmitter::new(config).unwrap();
    t.set_data(ms(0), &[9]).unwrap();
    let syncs: Vec<Frame> = [1, 2, 3, 4, 5, 6, 7, 8].map(sync_with).to_vec();
    let sent = run_syncs(&mut t, &syncs);
    // Counter 3 is the first SYNC, so every 2nd one is 4, 6, 8.
    let at: Vec<usize> = (0..sent.len()).filter(|&i| !sent[i].is_empty()).collect();
    assert_eq!(at, [3, 5, 7]);
    // A SYNC without counter ignores the start value.
    let mut t = PdoTransmitter::new(config).unwrap();
    t.set_data(ms(0), &[9]).unwrap();
    let sent = run_syncs(&mut t, &[sync(), sync(), sync(), sync()]);
    assert_eq!(
        sent,
        [
            vec![],
            vec![data(0x220, &[9])],
            vec![],
            vec![data(0x220, &[9])]
        ]
    );
}

#[test]
fn other_frames_do_not_count_as_sync() {
    let mut config = cfg(0x220, 1);
    config.sync_cob_id = 0x081;
    let mut t = PdoTransmitter::new(config).unwrap();
    t.set_data(ms(0), &[1]).unwrap();
    for frame in [
        sync(),
        data(0x081, &[1, 2]),
        Frame::remote(CanId::Standard(0x081), 0).unwrap(),
        Frame::new(CanId::Extended(0x081), &[]).unwrap(),
        data(0x220, &[]),
    ] {
        t.handle_frame(ms(1), &frame);
        assert!(frames(&mut t).is_empty(), "{frame} is not a SYNC on 0x081");
    }
    t.handle_frame(ms(2), &data(0x081, &[]));
    assert_eq!(frames(&mut t), [data(0x220, &[1])]);
}

#[test]
fn event_driven_sends_at_once_and_ignores_sync() {
    let mut t = transmitter(0x0000_0201, 255);
    assert_eq!(t.poll_timeout(), None);
    t.set_data(ms(5), &[1, 2, 3, 4, 5, 6, 7, 8]).unwrap();
    assert_eq!(frames(&mut t), [data(0x201, &[1, 2, 3, 4, 5, 6, 7, 8])]);
    t.set_data(ms(5), &[]).unwrap();
    assert_eq!(frames(&mut t), [data(0x201, &[])]);
    t.handle_frame(ms(6), &sync());
    assert!(frames(&mut t).is_empty());
    assert_eq!(t.poll_timeout(), None, "no inhibit time, no event timer");
}

#[test]
fn inhibit_time_coalesces_events_to_the_latest_data() {
    let mut config = cfg(0x201, 254);
    config.inhibit_time = InhibitTime(10); // 10 x 100 µs = 1 ms
    let mut t = PdoTransmitter::new(config).unwrap();
    t.set_data(us(0), &[0xA0]).unwrap();
    assert_eq!(frames(&mut t), [data(0x201, &[0xA0])]);
    assert_eq!(t.poll_timeout(), None, "nothing waits for the inhibit end");
    t.set_data(us(200), &[0xA1]).unwrap();
    t.set_data(us(500), &[0xA2]).unwrap();
    assert!(frames(&mut t).is_empty());
    assert_eq!(t.poll_timeout(), Some(us(1000)));
    t.handle_timeout(us(999));
    assert!(frames(&mut t).is_empty());
    t.handle_timeout(us(1000));
    assert_eq!(frames(&mut t), [data(0x201, &[0xA2])]);
    assert_eq!(t.poll_timeout(), None);
    // The deferred frame started a new inhibit time: 1000 to 2000 µs.
    t.set_data(us(1999), &[0xA3]).unwrap();
    assert!(frames(&mut t).is_empty());
    assert_eq!(t.poll_timeout(), Some(us(2000)));
    t.handle_timeout(us(2000));
    assert_eq!(frames(&mut t), [data(0x201, &[0xA3])]);
    // An event after the inhibit time goes out at once.
    t.set_data(us(3000), &[0xA4]).unwrap();
    assert_eq!(frames(&mut t), [data(0x201, &[0xA4])]);
}

#[test]
fn event_timer_resends_without_events() {
    let mut config = cfg(0x201, 254);
    config.event_timer = EventTimer(100);
    let mut t = PdoTransmitter::new(config).unwrap();
    assert_eq!(t.poll_timeout(), None, "no data yet");
    t.set_data(ms(0), &[7]).unwrap();
    assert_eq!(frames(&mut t), [data(0x201, &[7])]);
    assert_due(&mut t, 100, &[data(0x201, &[7])]);
    assert_eq!(t.poll_timeout(), Some(ms(200)));
    t.handle_timeout(ms(200));
    assert_eq!(frames(&mut t), [data(0x201, &[7])]);
    // An event restarts the timer.
    t.set_data(ms(250), &[8]).unwrap();
    assert_eq!(frames(&mut t), [data(0x201, &[8])]);
    assert_eq!(t.poll_timeout(), Some(ms(350)));
    // A clock jump gives one frame, not a burst.
    t.handle_timeout(ms(10_000));
    assert_eq!(frames(&mut t), [data(0x201, &[8])]);
    assert_eq!(t.poll_timeout(), Some(ms(10_100)));
}

#[test]
fn event_timer_within_the_inhibit_time_waits_for_its_end() {
    let mut config = cfg(0x201, 255);
    config.event_timer = EventTimer(1);
    config.inhibit_time = InhibitTime(25); // 2.5 ms
    let mut t = PdoTransmitter::new(config).unwrap();
    t.set_data(us(0), &[1]).unwrap();
    assert_eq!(frames(&mut t), [data(0x201, &[1])]);
    assert_eq!(t.poll_timeout(), Some(us(1000)));
    t.handle_timeout(us(1000));
    assert!(frames(&mut t).is_empty());
    assert_eq!(t.poll_timeout(), Some(us(2500)));
    t.handle_timeout(us(2500));
    assert_eq!(frames(&mut t), [data(0x201, &[1])]);
    assert_eq!(t.poll_timeout(), Some(us(3500)));
}

#[test]
fn an_unpolled_frame_is_replaced_by_newer_data() {
    let mut t = transmitter(0x201, 255);
    t.set_data(ms(0), &[1]).unwrap();
    t.set_data(ms(0), &[2]).unwrap();
    assert_eq!(frames(&mut t), [data(0x201, &[2])]);
}

#[test]
fn disabled_cob_id_sends_nothing() {
    for transmission_type in [0, 1, 255] {
        let mut config = cfg(0x8000_0201, transmission_type);
        config.event_timer = EventTimer(10);
        let mut t = PdoTransmitter::new(config).unwrap();
        assert!(!t.is_enabled());
        t.set_data(ms(0), &[1, 2]).unwrap();
        for i in 1..=5 {
            t.handle_frame(ms(i), &sync());
            t.handle_timeout(ms(i * 10));
            assert!(frames(&mut t).is_empty());
            assert_eq!(t.poll_timeout(), None);
        }
        assert_eq!(t.data(), [1, 2], "the data is kept");
    }
}

#[test]
fn enabling_and_disabling_at_run_time() {
    let mut config = cfg(0x201, 254);
    config.event_timer = EventTimer(50);
    let mut t = PdoTransmitter::new(config).unwrap();
    t.set_data(ms(0), &[1]).unwrap();
    // Disabling drops the unpolled frame and the timer.
    t.set_cob_id(ms(1), PdoCobId(0x8000_0201)).unwrap();
    assert!(frames(&mut t).is_empty());
    assert_eq!(t.poll_timeout(), None);
    t.set_data(ms(2), &[2]).unwrap();
    assert!(frames(&mut t).is_empty());
    // Enabling on another identifier starts the event timer.
    t.set_cob_id(ms(10), PdoCobId(0x202)).unwrap();
    assert_eq!(t.poll_timeout(), Some(ms(60)));
    t.handle_timeout(ms(60));
    assert_eq!(frames(&mut t), [data(0x202, &[2])]);
    assert_eq!(t.config().cob_id, PdoCobId(0x202));
    assert_eq!(
        t.set_cob_id(ms(61), PdoCobId(0x0000_0A02)),
        Err(CobIdError::OutOfRange(PdoCobId(0xA02)))
    );
    assert_eq!(t.can_id(), CanId::Standard(0x202));
}

#[test]
fn invalid_configurations_are_refused() {
    let bad = |config| PdoTransmitter::new(config).err();
    assert_eq!(
        bad(cfg(0x0000_0801, 255)),
        Some(TransmitterConfigError::CobId(CobIdError::OutOfRange(
            PdoCobId(0x801)
        )))
    );
    for t in 241..=253 {
        assert_eq!(
            bad(cfg(0x201, t)),
            Some(TransmitterConfigError::TransmissionType(
                TransmissionType::from_raw(t)
            ))
        );
    }
    // A 29-bit identifier goes out in an extended frame.
    let mut t = transmitter(0x2000_0201, 255);
    t.set_data(ms(0), &[7]).unwrap();
    assert_eq!(
        frames(&mut t),
        [Frame::new(CanId::Extended(0x201), &[7]).unwrap()]
    );
    let mut config = cfg(0x201, 1);
    config.sync_start = 241;
    assert_eq!(bad(config), Some(TransmitterConfigError::SyncStart(241)));
    let mut config = cfg(0x201, 1);
    config.sync_cob_id = 0x800;
    assert_eq!(bad(config), Some(TransmitterConfigError::SyncCobId(0x800)));
    // Bit 30 (no RTR) is fine.
    assert!(PdoTransmitter::new(cfg(0x4000_0201, 0)).is_ok());
    let mut t = transmitter(0x201, 255);
    assert_eq!(t.set_data(ms(0), &[0; 9]), Err(FrameError::TooLong(9)));
    assert!(frames(&mut t).is_empty());
}

#[test]
fn typed_data_from_a_generated_struct() {
    let node = NodeId::new(5).unwrap();
    let config =
        TransmitterConfig::from_pdo::<Command>(node, TransmissionType::EventDrivenProfile).unwrap();
    assert_eq!(config.cob_id, PdoCobId(0x205));
    let mut t = PdoTransmitter::new(config).unwrap();
    t.set(
        ms(0),
        &Command {
            word: 0x000F,
            long: -2,
        },
    )
    .unwrap();
    assert_eq!(
        frames(&mut t),
        [data(0x205, &[0x0F, 0x00, 0xFE, 0xFF, 0xFF, 0xFF])]
    );
}
