//! The master alone: the frames it sends (bytes written by hand from the
//! CiA 305 layouts), answers fed by hand, timeouts on a fake clock.

use super::*;
use crate::CanId;
use crate::cores::testing::ms;
use crate::od::NodeId;

fn sent(master: &mut LssMaster) -> Vec<[u8; 8]> {
    core::iter::from_fn(|| master.poll_transmit())
        .map(|frame| {
            assert_eq!(frame.id(), CanId::Standard(0x7E5));
            assert_eq!(frame.len(), 8);
            *frame.data_padded()
        })
        .collect()
}

fn events(master: &mut LssMaster) -> Vec<LssEvent> {
    core::iter::from_fn(|| master.poll_event()).collect()
}

fn answer(master: &mut LssMaster, now: Instant, data: [u8; 8]) {
    master.handle_frame(now, &Frame::standard(0x7E4, data, 8));
}

#[test]
fn unconfirmed_requests_end_when_sent() {
    let mut m = LssMaster::new();
    m.switch_global(ms(0), LssState::Configuration).unwrap();
    assert_eq!(m.poll_timeout(), None);
    assert!(events(&mut m).is_empty());
    assert_eq!(m.switch_global(ms(0), LssState::Waiting), Err(LssError));
    assert_eq!(sent(&mut m), [[0x04, 1, 0, 0, 0, 0, 0, 0]]);
    assert_eq!(events(&mut m), [LssEvent::Sent]);
    assert!(m.is_idle());
    m.activate_bit_timing(ms(0), 0x1234).unwrap();
    assert_eq!(sent(&mut m), [[0x15, 0x34, 0x12, 0, 0, 0, 0, 0]]);
    assert_eq!(events(&mut m), [LssEvent::Sent]);
}

#[test]
fn switch_selective_sends_four_frames() {
    let mut m = LssMaster::new();
    let id = Identity::new(0x0102_0304, 0x0506_0708, 0x090A_0B0C, 0x0D0E_0F10);
    m.switch_selective(ms(0), id).unwrap();
    assert_eq!(
        sent(&mut m),
        [
            [0x40, 0x04, 0x03, 0x02, 0x01, 0, 0, 0],
            [0x41, 0x08, 0x07, 0x06, 0x05, 0, 0, 0],
            [0x42, 0x0C, 0x0B, 0x0A, 0x09, 0, 0, 0],
            [0x43, 0x10, 0x0F, 0x0E, 0x0D, 0, 0, 0],
        ]
    );
    answer(&mut m, ms(3), [0x44, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(events(&mut m), [LssEvent::Selected]);
    assert_eq!(m.poll_timeout(), None);
}

#[test]
fn answers_before_the_request_is_sent_do_not_count() {
    let mut m = LssMaster::new();
    m.inquire_node_id(ms(0)).unwrap();
    answer(&mut m, ms(0), [0x5E, 7, 0, 0, 0, 0, 0, 0]);
    assert!(events(&mut m).is_empty());
    assert_eq!(sent(&mut m), [[0x5E, 0, 0, 0, 0, 0, 0, 0]]);
    answer(&mut m, ms(1), [0x5E, 8, 0, 0, 0, 0, 0, 0]);
    assert_eq!(events(&mut m), [LssEvent::NodeId(8)]);
}

#[test]
fn only_the_matching_answer_completes() {
    let mut m = LssMaster::new();
    m.inquire_identity(ms(0), IdentityField::Revision).unwrap();
    assert_eq!(sent(&mut m), [[0x5C, 0, 0, 0, 0, 0, 0, 0]]);
    // Another part, another service, the request's own COB-ID, 7 bytes.
    answer(&mut m, ms(1), [0x5B, 1, 0, 0, 0, 0, 0, 0]);
    answer(&mut m, ms(1), [0x11, 0, 0, 0, 0, 0, 0, 0]);
    m.handle_frame(
        ms(1),
        &Frame::standard(0x7E5, [0x5C, 1, 0, 0, 0, 0, 0, 0], 8),
    );
    m.handle_frame(
        ms(1),
        &Frame::standard(0x7E4, [0x5C, 1, 0, 0, 0, 0, 0, 0], 7),
    );
    assert!(events(&mut m).is_empty());
    answer(&mut m, ms(2), [0x5C, 0x02, 0x00, 0x01, 0x00, 0, 0, 0]);
    assert_eq!(
        events(&mut m),
        [LssEvent::Identity {
            field: IdentityField::Revision,
            value: 0x0001_0002
        }]
    );
}

#[test]
fn configuration_errors_are_reported() {
    let mut m = LssMaster::new();
    m.configure_node_id(ms(0), NodeId::new(5).unwrap()).unwrap();
    assert_eq!(sent(&mut m), [[0x11, 5, 0, 0, 0, 0, 0, 0]]);
    answer(&mut m, ms(1), [0x11, 1, 0, 0, 0, 0, 0, 0]);
    m.configure_bit_timing(ms(1), BitTiming { table: 0, index: 4 })
        .unwrap();
    assert_eq!(sent(&mut m), [[0x13, 0, 4, 0, 0, 0, 0, 0]]);
    answer(&mut m, ms(2), [0x13, 0xFF, 0x21, 0, 0, 0, 0, 0]);
    m.store_configuration(ms(2)).unwrap();
    assert_eq!(sent(&mut m), [[0x17, 0, 0, 0, 0, 0, 0, 0]]);
    answer(&mut m, ms(3), [0x17, 2, 0, 0, 0, 0, 0, 0]);
    m.configure_node_id(ms(3), LssNodeId::Unconfigured).unwrap();
    assert_eq!(sent(&mut m), [[0x11, 0xFF, 0, 0, 0, 0, 0, 0]]);
    answer(&mut m, ms(4), [0x11, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(
        events(&mut m),
        [
            LssEvent::ConfigureFailed {
                service: ConfigureService::NodeId,
                error: 1,
                spec: 0
            },
            LssEvent::ConfigureFailed {
                service: ConfigureService::BitTiming,
                error: 0xFF,
                spec: 0x21
            },
            LssEvent::ConfigureFailed {
                service: ConfigureService::Store,
                error: 2,
                spec: 0
            },
            LssEvent::NodeIdConfigured,
        ]
    );
}

#[test]
fn confirmed_requests_time_out() {
    let mut m = LssMaster::with_timeout(Duration::from_millis(50));
    m.store_configuration(ms(10)).unwrap();
    sent(&mut m);
    assert_eq!(m.poll_timeout(), Some(ms(60)));
    m.handle_timeout(ms(59));
    assert!(events(&mut m).is_empty());
    m.handle_timeout(ms(60));
    assert_eq!(events(&mut m), [LssEvent::NoResponse]);
    assert!(m.is_idle());
    assert_eq!(m.poll_timeout(), None);
    // A late answer is ignored.
    answer(&mut m, ms(61), [0x17, 0, 0, 0, 0, 0, 0, 0]);
    assert!(events(&mut m).is_empty());
}

#[test]
fn identify_waits_out_the_timeout() {
    let mut m = LssMaster::new();
    m.identify_remote(ms(0), IdentityRange::product(0x17A, 2))
        .unwrap();
    assert_eq!(
        sent(&mut m),
        [
            [0x46, 0x7A, 0x01, 0, 0, 0, 0, 0],
            [0x47, 0x02, 0, 0, 0, 0, 0, 0],
            [0x48, 0, 0, 0, 0, 0, 0, 0],
            [0x49, 0xFF, 0xFF, 0xFF, 0xFF, 0, 0, 0],
            [0x4A, 0, 0, 0, 0, 0, 0, 0],
            [0x4B, 0xFF, 0xFF, 0xFF, 0xFF, 0, 0, 0],
        ]
    );
    answer(&mut m, ms(1), [0x4F, 0, 0, 0, 0, 0, 0, 0]);
    answer(&mut m, ms(2), [0x4F, 0, 0, 0, 0, 0, 0, 0]);
    assert!(events(&mut m).is_empty());
    m.handle_timeout(ms(100));
    assert_eq!(events(&mut m), [LssEvent::SlavePresent]);

    // Non-configured expects 0x50, not 0x4F.
    m.identify_non_configured(ms(100)).unwrap();
    assert_eq!(sent(&mut m), [[0x4C, 0, 0, 0, 0, 0, 0, 0]]);
    answer(&mut m, ms(101), [0x4F, 0, 0, 0, 0, 0, 0, 0]);
    m.handle_timeout(ms(200));
    assert_eq!(events(&mut m), [LssEvent::NoResponse]);
    m.identify_non_configured(ms(200)).unwrap();
    sent(&mut m);
    answer(&mut m, ms(201), [0x50, 0, 0, 0, 0, 0, 0, 0]);
    m.handle_timeout(ms(300));
    assert_eq!(events(&mut m), [LssEvent::SlavePresent]);
}

#[test]
fn fastscan_without_answer_is_not_found_after_one_timeout() {
    let mut m = LssMaster::new();
    m.fastscan(ms(0), KnownIdentity::NONE).unwrap();
    assert_eq!(sent(&mut m), [[0x51, 0, 0, 0, 0, 0x80, 0, 0]]);
    assert_eq!(m.poll_timeout(), Some(ms(100)));
    m.handle_timeout(ms(100));
    assert_eq!(events(&mut m), [LssEvent::NotFound]);
    assert!(m.is_idle());
}

#[test]
fn fastscan_steps_follow_the_answers() {
    let mut m = LssMaster::new();
    m.fastscan(ms(0), KnownIdentity::NONE).unwrap();
    sent(&mut m);
    answer(&mut m, ms(1), [0x4F, 0, 0, 0, 0, 0, 0, 0]);
    // The answer does not end the step early: the window is waited out.
    assert_eq!(sent(&mut m), Vec::<[u8; 8]>::new());
    m.handle_timeout(ms(100));
    // Bit 31 of the vendor id, candidate 0, sub 0, next 0.
    assert_eq!(sent(&mut m), [[0x51, 0, 0, 0, 0, 31, 0, 0]]);
    assert_eq!(m.poll_timeout(), Some(ms(200)));
    // No answer: bit 31 is set; the next step checks bit 30.
    m.handle_timeout(ms(200));
    assert_eq!(sent(&mut m), [[0x51, 0, 0, 0, 0x80, 30, 0, 0]]);
    m.cancel();
    assert!(m.is_idle());
    assert_eq!(m.poll_timeout(), None);
    assert_eq!(sent(&mut m), Vec::<[u8; 8]>::new());
    assert!(events(&mut m).is_empty());
}
