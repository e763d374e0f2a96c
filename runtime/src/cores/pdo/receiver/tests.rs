use super::*;
use crate::CanId;
use crate::cores::pdo::test_pdos::Status;
use crate::cores::testing::{data, ms};
use crate::od::{NodeId, PdoDirection};

fn cob(raw: u32) -> PdoCobId {
    PdoCobId(raw)
}

fn sid(id: u16) -> CanId {
    CanId::Standard(id)
}

fn events<const N: usize>(r: &mut PdoReceiver<N>) -> Vec<PdoEvent> {
    core::iter::from_fn(|| r.poll_event()).collect()
}

fn received(cob_id: u16, bytes: &[u8], at: Instant) -> PdoEvent {
    let mut data = [0u8; 8];
    data[..bytes.len()].copy_from_slice(bytes);
    PdoEvent::Received {
        can_id: sid(cob_id),
        data,
        len: bytes.len(),
        at,
    }
}

#[test]
fn stores_and_reports_watched_pdos() {
    let mut r: PdoReceiver<2> = PdoReceiver::new();
    r.watch(cob(0x1A0), 3, None).unwrap();
    // bit 30 (no RTR) set, as devices often report it.
    r.watch(cob(0x4000_02A0), 0, None).unwrap();
    assert_eq!(r.latest_data(sid(0x1A0)), None);
    r.handle_frame(ms(1), &data(0x1A0, &[1, 2, 3]));
    r.handle_frame(ms(2), &data(0x2A0, &[]));
    r.handle_frame(ms(3), &data(0x3A0, &[9])); // not watched
    r.handle_frame(ms(4), &Frame::remote(CanId::Standard(0x1A0), 3).unwrap());
    r.handle_frame(
        ms(5),
        &Frame::new(CanId::Extended(0x1A0), &[4, 5, 6]).unwrap(),
    );
    assert_eq!(
        events(&mut r),
        [
            received(0x1A0, &[1, 2, 3], ms(1)),
            received(0x2A0, &[], ms(2))
        ]
    );
    assert_eq!(r.latest_data(sid(0x1A0)), Some(&[1, 2, 3][..]));
    assert_eq!(r.latest_data(sid(0x2A0)), Some(&[][..]));
    assert_eq!(r.last_received(sid(0x1A0)), Some(ms(1)));
    assert_eq!(r.poll_timeout(), None);
    assert_eq!(r.watch(cob(0x3A0), 1, None), Err(WatchError::Full));
}

#[test]
fn wrong_length_is_a_length_error_and_keeps_the_old_data() {
    let mut r: PdoReceiver<1> = PdoReceiver::new();
    r.watch(cob(0x1A0), 4, None).unwrap();
    r.handle_frame(ms(1), &data(0x1A0, &[1, 2, 3, 4]));
    r.handle_frame(ms(2), &data(0x1A0, &[5, 6]));
    r.handle_frame(ms(3), &data(0x1A0, &[5, 6, 7, 8, 9]));
    let got = events(&mut r);
    assert_eq!(
        got,
        [
            received(0x1A0, &[1, 2, 3, 4], ms(1)),
            PdoEvent::LengthError {
                can_id: sid(0x1A0),
                expected: 4,
                actual: 2
            },
            PdoEvent::LengthError {
                can_id: sid(0x1A0),
                expected: 4,
                actual: 5
            },
        ]
    );
    assert_eq!(got[1].emcy_code(), Some(0x8210));
    assert_eq!(got[2].emcy_code(), Some(0x8220));
    assert_eq!(got[0].emcy_code(), None);
    assert_eq!(got[0].data(), Some(&[1, 2, 3, 4][..]));
    assert_eq!(r.latest_data(sid(0x1A0)), Some(&[1, 2, 3, 4][..]));
    assert_eq!(r.last_received(sid(0x1A0)), Some(ms(1)));
}

#[test]
fn timeout_is_reported_once_per_silence() {
    let mut r: PdoReceiver<2> = PdoReceiver::new();
    r.watch(cob(0x1A0), 1, Some(Duration::from_millis(100)))
        .unwrap();
    // Armed by the first reception only.
    assert_eq!(r.poll_timeout(), None);
    r.handle_frame(ms(10), &data(0x1A0, &[1]));
    assert_eq!(r.poll_timeout(), Some(ms(110)));
    r.handle_frame(ms(50), &data(0x1A0, &[2]));
    assert_eq!(r.poll_timeout(), Some(ms(150)));
    // A frame of the wrong length does not count as a reception.
    r.handle_frame(ms(60), &data(0x1A0, &[]));
    assert_eq!(r.poll_timeout(), Some(ms(150)));
    events(&mut r);
    r.handle_timeout(ms(149));
    assert!(events(&mut r).is_empty());
    r.handle_timeout(ms(150));
    assert_eq!(events(&mut r), [PdoEvent::Timeout { can_id: sid(0x1A0) }]);
    assert!(r.is_timed_out(sid(0x1A0)));
    assert_eq!(r.poll_timeout(), None);
    r.handle_timeout(ms(1000));
    assert!(events(&mut r).is_empty(), "once per silence");
    // The next reception re-arms it.
    r.handle_frame(ms(2000), &data(0x1A0, &[3]));
    assert!(!r.is_timed_out(sid(0x1A0)));
    assert_eq!(events(&mut r), [received(0x1A0, &[3], ms(2000))]);
    assert_eq!(r.poll_timeout(), Some(ms(2100)));
    r.handle_timeout(ms(2100));
    assert_eq!(events(&mut r), [PdoEvent::Timeout { can_id: sid(0x1A0) }]);
}

#[test]
fn timeouts_of_several_slots() {
    let mut r: PdoReceiver<3> = PdoReceiver::new();
    r.watch(cob(0x181), 2, Some(Duration::from_millis(30)))
        .unwrap();
    r.watch(cob(0x182), 2, Some(Duration::from_millis(20)))
        .unwrap();
    r.watch(cob(0x183), 2, None).unwrap();
    for id in [0x181, 0x182, 0x183] {
        r.handle_frame(ms(0), &data(id, &[0, 0]));
    }
    events(&mut r);
    assert_eq!(r.poll_timeout(), Some(ms(20)));
    r.handle_timeout(ms(20));
    assert_eq!(events(&mut r), [PdoEvent::Timeout { can_id: sid(0x182) }]);
    assert_eq!(r.poll_timeout(), Some(ms(30)));
    r.handle_timeout(ms(30));
    assert_eq!(events(&mut r), [PdoEvent::Timeout { can_id: sid(0x181) }]);
    assert_eq!(r.poll_timeout(), None);
    // A timeout set later counts from the last reception.
    r.set_timeout(sid(0x183), Some(Duration::from_millis(50)))
        .unwrap();
    assert_eq!(r.poll_timeout(), Some(ms(50)));
    r.set_timeout(sid(0x183), None).unwrap();
    assert_eq!(r.poll_timeout(), None);
    assert_eq!(
        r.set_timeout(sid(0x184), None),
        Err(WatchError::NotWatched(sid(0x184)))
    );
}

#[test]
fn watch_rules() {
    let mut r: PdoReceiver<2> = PdoReceiver::new();
    assert_eq!(
        r.watch(cob(0x8000_01A0), 8, None),
        Err(WatchError::Disabled(cob(0x8000_01A0)))
    );
    assert_eq!(
        r.watch(cob(0x0000_09A0), 8, None),
        Err(WatchError::CobId(CobIdError::OutOfRange(cob(0x9A0))))
    );
    assert_eq!(r.watch(cob(0x1A0), 9, None), Err(WatchError::Length(9)));
    // Watching again replaces the settings and forgets the data.
    r.watch(cob(0x1A0), 1, None).unwrap();
    r.handle_frame(ms(0), &data(0x1A0, &[1]));
    r.watch(cob(0x1A0), 2, None).unwrap();
    assert_eq!(r.latest_data(sid(0x1A0)), None);
    r.watch(cob(0x1A1), 2, None).unwrap();
    assert_eq!(r.watch(cob(0x1A2), 2, None), Err(WatchError::Full));
    assert!(r.unwatch(sid(0x1A0)));
    assert!(!r.unwatch(sid(0x1A0)));
    assert!(!r.is_watched(sid(0x1A0)));
    r.watch(cob(0x1A2), 2, None).unwrap();
    assert!(r.is_watched(sid(0x1A2)));
    let mut none: PdoReceiver<0> = PdoReceiver::new();
    assert_eq!(none.watch(cob(0x1A0), 1, None), Err(WatchError::Full));
    none.handle_frame(ms(0), &data(0x1A0, &[1]));
    assert!(none.poll_event().is_none());
}

#[test]
fn full_event_queue_drops_the_oldest() {
    let mut r: PdoReceiver<1> = PdoReceiver::new();
    r.watch(cob(0x1A0), 1, None).unwrap();
    for i in 0..(RECEIVER_EVENTS as u8 + 3) {
        r.handle_frame(ms(u64::from(i)), &data(0x1A0, &[i]));
    }
    assert_eq!(r.dropped_events(), 3);
    let got = events(&mut r);
    assert_eq!(got.len(), RECEIVER_EVENTS);
    assert_eq!(got[0], received(0x1A0, &[3], ms(3)));
    assert_eq!(
        r.latest_data(sid(0x1A0)),
        Some(&[RECEIVER_EVENTS as u8 + 2][..])
    );
}

/// A PDO without a default COB-ID.
struct NoDefault;

impl od::Pdo for NoDefault {
    const DIRECTION: PdoDirection = PdoDirection::Tpdo;
    const NUMBER: u16 = 5;
    const COMMUNICATION_INDEX: u16 = 0x1804;
    const MAPPING_INDEX: u16 = 0x1A04;
    const LEN: usize = 0;
    const MAPPING: &'static [u32] = &[];
    fn default_cob_id(_: NodeId) -> Option<PdoCobId> {
        None
    }
    fn decode(_: &[u8]) -> Result<Self, PdoLengthError> {
        Ok(NoDefault)
    }
    fn encode_into(&self, _: &mut [u8; 8]) -> usize {
        0
    }
}

#[test]
fn typed_access_decodes_the_generated_struct() {
    let node = NodeId::new(3).unwrap();
    let mut r: PdoReceiver<4> = PdoReceiver::new();
    let id = r.watch_pdo::<Status>(node).unwrap();
    assert_eq!(id, sid(0x183));
    assert!(r.latest::<Status>(id).is_none());
    // Status word 0x0237, position -1000 (0xFFFFFC18).
    r.handle_frame(ms(1), &data(0x183, &[0x37, 0x02, 0x18, 0xFC, 0xFF, 0xFF]));
    assert_eq!(
        r.latest::<Status>(sid(0x183)),
        Some(Ok(Status {
            word: 0x0237,
            long: -1000
        }))
    );
    // A struct of another length gives the length error.
    r.watch(cob(0x283), 4, None).unwrap();
    r.handle_frame(ms(2), &data(0x283, &[1, 2, 3, 4]));
    assert_eq!(
        r.latest::<Status>(sid(0x283)),
        Some(Err(PdoLengthError {
            expected: 6,
            actual: 4
        }))
    );
    assert_eq!(
        r.watch_pdo::<NoDefault>(node),
        Err(WatchError::NoDefaultCobId)
    );
}
