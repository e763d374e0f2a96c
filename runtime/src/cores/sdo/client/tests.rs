//! Client tests. Every expected frame is written by hand from the CiA 301
//! layouts (command byte, index LE, sub-index, data); server frames too.

mod block;
mod random;
mod real_devices;
mod stream;

use super::*;
use crate::frame::CanId;
use crate::sdo::Channel;
use crate::sdo::proto::ParseError;
use crate::{Frame, Service};
use core::time::Duration;

const REQUEST: u16 = 0x601;
const RESPONSE: u16 = 0x581;

fn config() -> ClientConfig {
    ClientConfig::new(Channel::standard(REQUEST, RESPONSE))
}

fn client() -> SdoClient {
    SdoClient::new(config())
}

fn ms(millis: u64) -> Instant {
    Instant::from_millis(millis)
}

/// The server's frame `bytes` reaches the client at `now`.
fn reply(client: &mut SdoClient, now: Instant, bytes: [u8; 8]) {
    let frame = Frame::new(CanId::Standard(RESPONSE), &bytes).unwrap();
    client.handle_frame(now, &frame);
}

/// Every frame the client wants to send, checked to be 8-byte data frames on
/// the request id.
fn sent(client: &mut SdoClient) -> Vec<[u8; 8]> {
    let mut frames = Vec::new();
    while let Some(frame) = client.poll_transmit() {
        assert_eq!(frame.id(), CanId::Standard(REQUEST));
        assert!(!frame.is_remote());
        frames.push(*frame.data_padded());
        assert_eq!(frame.len(), 8);
    }
    frames
}

/// Exactly one frame to send.
fn one(client: &mut SdoClient) -> [u8; 8] {
    let frames = sent(client);
    assert_eq!(frames.len(), 1, "{frames:02X?}");
    frames[0]
}

fn events(client: &mut SdoClient) -> Vec<ClientEvent> {
    core::iter::from_fn(|| client.poll_event()).collect()
}

fn failed(index: u16, sub: u8, error: SdoError) -> Vec<ClientEvent> {
    vec![ClientEvent::Failed { index, sub, error }]
}

fn local(code: AbortCode) -> SdoError {
    SdoError::LocalAbort(code)
}

fn crc16_xmodem(data: &[u8]) -> u16 {
    crc::Crc::<u16>::new(&crc::CRC_16_XMODEM).checksum(data)
}

#[test]
fn expedited_download_of_two_bytes() {
    let mut c = client();
    assert!(c.is_idle());
    assert_eq!(c.poll_timeout(), None);
    c.download(ms(0), 0x1017, 0, &[0xE8, 0x03]).unwrap();
    assert!(!c.is_idle());
    assert_eq!(
        one(&mut c),
        [0x2B, 0x17, 0x10, 0x00, 0xE8, 0x03, 0x00, 0x00]
    );
    assert_eq!(
        c.progress(),
        Some(Progress {
            done: 0,
            total: Some(2)
        })
    );
    assert_eq!(c.poll_timeout(), Some(ms(500)));
    reply(&mut c, ms(10), [0x60, 0x17, 0x10, 0x00, 0, 0, 0, 0]);
    assert_eq!(
        events(&mut c),
        vec![ClientEvent::Downloaded {
            index: 0x1017,
            sub: 0
        }]
    );
    assert!(c.is_idle());
    assert!(sent(&mut c).is_empty());
    assert_eq!(c.poll_timeout(), None);
    assert_eq!(c.progress(), None);
}

#[test]
fn expedited_uploads_with_and_without_size() {
    let mut c = client();
    c.upload(ms(0), 0x1000, 0).unwrap();
    assert_eq!(one(&mut c), [0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]);
    // e=1, s=1, n=0: four bytes.
    reply(
        &mut c,
        ms(1),
        [0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00],
    );
    assert_eq!(
        events(&mut c),
        vec![ClientEvent::Uploaded {
            index: 0x1000,
            sub: 0,
            data: vec![0x92, 0x01, 0x02, 0x00],
            padded: false
        }]
    );
    // e=1, s=1, n=3: one byte.
    c.upload(ms(2), 0x1001, 0).unwrap();
    assert_eq!(one(&mut c), [0x40, 0x01, 0x10, 0x00, 0, 0, 0, 0]);
    reply(
        &mut c,
        ms(3),
        [0x4F, 0x01, 0x10, 0x00, 0x05, 0xAA, 0xAA, 0xAA],
    );
    assert_eq!(
        events(&mut c),
        vec![ClientEvent::Uploaded {
            index: 0x1001,
            sub: 0,
            data: vec![0x05],
            padded: false
        }]
    );
    // e=1, s=0: size not indicated, all four bytes are taken.
    c.upload(ms(4), 0x2000, 1).unwrap();
    assert_eq!(one(&mut c), [0x40, 0x00, 0x20, 0x01, 0, 0, 0, 0]);
    reply(&mut c, ms(5), [0x42, 0x00, 0x20, 0x01, 1, 2, 3, 4]);
    assert_eq!(
        events(&mut c),
        vec![ClientEvent::Uploaded {
            index: 0x2000,
            sub: 1,
            data: vec![1, 2, 3, 4],
            padded: true
        }]
    );
}

#[test]
fn segmented_upload_of_hello_world() {
    let mut c = client();
    c.upload(ms(0), 0x1008, 0).unwrap();
    assert_eq!(one(&mut c), [0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0]);
    // Segmented, size indicated: 12 bytes.
    reply(&mut c, ms(1), [0x41, 0x08, 0x10, 0x00, 12, 0, 0, 0]);
    assert_eq!(one(&mut c), [0x60, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(c.poll_timeout(), Some(ms(501)));
    // Toggle 0, 7 bytes, not last.
    reply(
        &mut c,
        ms(2),
        [0x00, b'H', b'e', b'l', b'l', b'o', b',', b' '],
    );
    assert_eq!(one(&mut c), [0x70, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(
        c.progress(),
        Some(Progress {
            done: 7,
            total: Some(12)
        })
    );
    // Toggle 1, n=2 (5 bytes), last: 0x10 | 2 << 1 | 1.
    reply(&mut c, ms(3), [0x15, b'w', b'o', b'r', b'l', b'd', 0, 0]);
    assert!(sent(&mut c).is_empty());
    assert_eq!(
        events(&mut c),
        vec![ClientEvent::Uploaded {
            index: 0x1008,
            sub: 0,
            data: b"Hello, world".to_vec(),
            padded: false
        }]
    );
    assert!(c.is_idle());
}

#[test]
fn segmented_download_of_ten_bytes() {
    let mut c = client();
    c.download(ms(0), 0x2000, 0, b"0123456789").unwrap();
    // Segmented, size indicated: 0x21, size 10.
    assert_eq!(one(&mut c), [0x21, 0x00, 0x20, 0x00, 10, 0, 0, 0]);
    reply(&mut c, ms(1), [0x60, 0x00, 0x20, 0x00, 0, 0, 0, 0]);
    assert_eq!(
        one(&mut c),
        [0x00, b'0', b'1', b'2', b'3', b'4', b'5', b'6']
    );
    reply(&mut c, ms(2), [0x20, 0, 0, 0, 0, 0, 0, 0]);
    // Toggle 1, n=4 (3 bytes), last: 0x10 | 4 << 1 | 1.
    assert_eq!(one(&mut c), [0x19, b'7', b'8', b'9', 0, 0, 0, 0]);
    reply(&mut c, ms(3), [0x30, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(
        events(&mut c),
        vec![ClientEvent::Downloaded {
            index: 0x2000,
            sub: 0
        }]
    );
}

#[test]
fn empty_and_forced_segmented_downloads() {
    let mut c = client();
    c.download(ms(0), 0x2001, 2, &[]).unwrap();
    assert_eq!(one(&mut c), [0x21, 0x01, 0x20, 0x02, 0, 0, 0, 0]);
    reply(&mut c, ms(1), [0x60, 0x01, 0x20, 0x02, 0, 0, 0, 0]);
    // Toggle 0, n=7 (no data), last.
    assert_eq!(one(&mut c), [0x0F, 0, 0, 0, 0, 0, 0, 0]);
    reply(&mut c, ms(2), [0x20, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(
        events(&mut c),
        vec![ClientEvent::Downloaded {
            index: 0x2001,
            sub: 2
        }]
    );

    c.download_with(ms(3), 0x2001, 3, &[0xAB, 0xCD], Method::Segmented)
        .unwrap();
    assert_eq!(one(&mut c), [0x21, 0x01, 0x20, 0x03, 2, 0, 0, 0]);
    reply(&mut c, ms(4), [0x60, 0x01, 0x20, 0x03, 0, 0, 0, 0]);
    // Toggle 0, n=5, last.
    assert_eq!(one(&mut c), [0x0B, 0xAB, 0xCD, 0, 0, 0, 0, 0]);
}

#[test]
fn wrong_toggle_aborts() {
    let mut c = client();
    c.upload(ms(0), 0x1008, 0).unwrap();
    sent(&mut c);
    reply(&mut c, ms(1), [0x41, 0x08, 0x10, 0x00, 14, 0, 0, 0]);
    assert_eq!(one(&mut c), [0x60, 0, 0, 0, 0, 0, 0, 0]);
    // The first segment must carry toggle 0.
    reply(&mut c, ms(2), [0x10, 1, 2, 3, 4, 5, 6, 7]);
    assert_eq!(
        one(&mut c),
        [0x80, 0x08, 0x10, 0x00, 0x00, 0x00, 0x03, 0x05]
    );
    assert_eq!(
        events(&mut c),
        failed(0x1008, 0, local(AbortCode::ToggleBitNotAlternated))
    );
    assert!(c.is_idle());

    // Download: the server echoes toggle 1 for the first segment.
    c.download(ms(3), 0x2000, 0, b"0123456789").unwrap();
    sent(&mut c);
    reply(&mut c, ms(4), [0x60, 0x00, 0x20, 0x00, 0, 0, 0, 0]);
    sent(&mut c);
    reply(&mut c, ms(5), [0x30, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(
        one(&mut c),
        [0x80, 0x00, 0x20, 0x00, 0x00, 0x00, 0x03, 0x05]
    );
    assert_eq!(
        events(&mut c),
        failed(0x2000, 0, local(AbortCode::ToggleBitNotAlternated))
    );
}

#[test]
fn remote_abort_ends_the_transfer_silently() {
    let mut c = client();
    c.download(ms(0), 0x6040, 0, &[1, 2, 3, 4]).unwrap();
    assert_eq!(one(&mut c), [0x23, 0x40, 0x60, 0x00, 1, 2, 3, 4]);
    reply(
        &mut c,
        ms(1),
        [0x80, 0x40, 0x60, 0x00, 0x02, 0x00, 0x01, 0x06],
    );
    assert!(sent(&mut c).is_empty());
    assert_eq!(
        events(&mut c),
        failed(0x6040, 0, SdoError::RemoteAbort(AbortCode::WriteReadOnly))
    );
    assert!(c.is_idle());

    // An abort naming another object still ends the running transfer.
    c.upload(ms(2), 0x1018, 1).unwrap();
    sent(&mut c);
    reply(
        &mut c,
        ms(3),
        [0x80, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x08],
    );
    assert!(sent(&mut c).is_empty());
    assert_eq!(
        events(&mut c),
        failed(0x1018, 1, SdoError::RemoteAbort(AbortCode::GeneralError))
    );
}

#[test]
fn timeout_sends_the_timeout_abort() {
    let mut c = client();
    c.upload(ms(1000), 0x1008, 0).unwrap();
    sent(&mut c);
    assert_eq!(c.poll_timeout(), Some(ms(1500)));
    c.handle_timeout(ms(1499));
    assert!(sent(&mut c).is_empty());
    assert!(events(&mut c).is_empty());
    // Every answer renews the deadline.
    reply(&mut c, ms(1400), [0x41, 0x08, 0x10, 0x00, 20, 0, 0, 0]);
    sent(&mut c);
    assert_eq!(c.poll_timeout(), Some(ms(1900)));
    c.handle_timeout(ms(1900));
    assert_eq!(
        one(&mut c),
        [0x80, 0x08, 0x10, 0x00, 0x00, 0x00, 0x04, 0x05]
    );
    assert_eq!(events(&mut c), failed(0x1008, 0, SdoError::Timeout));
    assert!(c.is_idle());
    assert_eq!(c.poll_timeout(), None);
    c.handle_timeout(ms(5000));
    assert!(sent(&mut c).is_empty());
}

#[test]
fn initiate_response_for_another_object_aborts() {
    let mut c = client();
    c.upload(ms(0), 0x1008, 0).unwrap();
    sent(&mut c);
    reply(&mut c, ms(1), [0x43, 0x09, 0x10, 0x00, 1, 2, 3, 4]);
    // 0x06040043, general parameter incompatibility, for our object.
    assert_eq!(
        one(&mut c),
        [0x80, 0x08, 0x10, 0x00, 0x43, 0x00, 0x04, 0x06]
    );
    assert_eq!(
        events(&mut c),
        failed(0x1008, 0, local(AbortCode::ParameterIncompatible))
    );

    c.download(ms(2), 0x2000, 1, &[7]).unwrap();
    sent(&mut c);
    reply(&mut c, ms(3), [0x60, 0x00, 0x20, 0x02, 0, 0, 0, 0]);
    assert_eq!(
        one(&mut c),
        [0x80, 0x00, 0x20, 0x01, 0x43, 0x00, 0x04, 0x06]
    );
}

#[test]
fn unexpected_or_unparsable_responses_abort_with_invalid_command() {
    let invalid = [0x80, 0x00, 0x10, 0x00, 0x01, 0x00, 0x04, 0x05];
    let bad = |frame: &[u8], error| {
        let mut bytes = [0u8; 8];
        bytes[..frame.len()].copy_from_slice(frame);
        SdoError::BadResponse {
            frame: bytes,
            len: frame.len() as u8,
            error,
        }
    };
    let answers: [(&[u8], SdoError); 3] = [
        // A download initiate response to an upload: a valid frame that
        // does not fit the transfer.
        (
            &[0x60, 0x00, 0x10, 0x00, 0, 0, 0, 0],
            local(AbortCode::InvalidCommand),
        ),
        // No such command specifier: the error names the frame.
        (
            &[0xE0, 0, 0, 0, 0, 0, 0, 0],
            bad(&[0xE0, 0, 0, 0, 0, 0, 0, 0], ParseError::Command(0xE0)),
        ),
        // An expedited response of 4 bytes has 8.
        (
            &[0x43, 0x00, 0x10],
            bad(&[0x43, 0x00, 0x10], ParseError::Short { len: 3, needed: 8 }),
        ),
    ];
    for (answer, error) in answers {
        let mut c = client();
        c.upload(ms(0), 0x1000, 0).unwrap();
        sent(&mut c);
        let frame = Frame::new(CanId::Standard(RESPONSE), answer).unwrap();
        c.handle_frame(ms(1), &frame);
        assert_eq!(one(&mut c), invalid);
        assert_eq!(events(&mut c), failed(0x1000, 0, error));
        assert_eq!(error.code(), AbortCode::InvalidCommand);
    }
}

#[test]
fn foreign_frames_are_ignored() {
    let mut c = client();
    // Idle: even a valid response is ignored.
    reply(&mut c, ms(0), [0x43, 0x00, 0x10, 0x00, 1, 2, 3, 4]);
    assert!(sent(&mut c).is_empty() && events(&mut c).is_empty());

    c.upload(ms(0), 0x1000, 0).unwrap();
    sent(&mut c);
    let answer = [0x43, 0x00, 0x10, 0x00, 1, 2, 3, 4];
    let foreign = [
        Frame::new(CanId::Standard(0x582), &answer).unwrap(),
        Frame::new(CanId::Standard(REQUEST), &answer).unwrap(),
        Frame::new(CanId::Extended(u32::from(RESPONSE)), &answer).unwrap(),
        Frame::remote(CanId::Standard(RESPONSE), 8).unwrap(),
    ];
    for frame in &foreign {
        c.handle_frame(ms(1), frame);
    }
    assert!(sent(&mut c).is_empty() && events(&mut c).is_empty());
    assert!(!c.is_idle());
    reply(&mut c, ms(2), answer);
    assert_eq!(
        events(&mut c),
        vec![ClientEvent::Uploaded {
            index: 0x1000,
            sub: 0,
            data: vec![1, 2, 3, 4],
            padded: false
        }]
    );
}

#[test]
fn upload_length_must_match_the_announced_size() {
    let mismatch = [0x80, 0x08, 0x10, 0x00, 0x10, 0x00, 0x07, 0x06];
    // Fewer bytes than announced.
    let mut c = client();
    c.upload(ms(0), 0x1008, 0).unwrap();
    sent(&mut c);
    reply(&mut c, ms(1), [0x41, 0x08, 0x10, 0x00, 12, 0, 0, 0]);
    sent(&mut c);
    reply(&mut c, ms(2), [0x05, b'w', b'o', b'r', b'l', b'd', 0, 0]);
    assert_eq!(one(&mut c), mismatch);
    assert_eq!(
        events(&mut c),
        failed(0x1008, 0, local(AbortCode::LengthMismatch))
    );
    // More bytes than announced: aborted at the segment that overflows.
    c.upload(ms(3), 0x1008, 0).unwrap();
    sent(&mut c);
    reply(&mut c, ms(4), [0x41, 0x08, 0x10, 0x00, 3, 0, 0, 0]);
    sent(&mut c);
    reply(&mut c, ms(5), [0x00, 1, 2, 3, 4, 5, 6, 7]);
    assert_eq!(one(&mut c), mismatch);
    // The buffer of the first upload is reused; nothing grew beyond it.
    assert_eq!(c.buf.capacity(), 12);
}

#[test]
fn unannounced_upload_stops_at_max_upload() {
    let mut c = SdoClient::new(ClientConfig {
        max_upload: 10,
        ..config()
    });
    c.upload(ms(0), 0x1008, 0).unwrap();
    sent(&mut c);
    // Segmented, size not indicated.
    reply(&mut c, ms(1), [0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0]);
    assert_eq!(one(&mut c), [0x60, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(c.progress().unwrap().total, None);
    reply(&mut c, ms(2), [0x00, 1, 2, 3, 4, 5, 6, 7]);
    assert_eq!(one(&mut c), [0x70, 0, 0, 0, 0, 0, 0, 0]);
    reply(&mut c, ms(3), [0x10, 8, 9, 10, 11, 12, 13, 14]);
    assert_eq!(
        one(&mut c),
        [0x80, 0x08, 0x10, 0x00, 0x05, 0x00, 0x04, 0x05]
    );
    assert_eq!(
        events(&mut c),
        failed(0x1008, 0, local(AbortCode::OutOfMemory))
    );
    assert!(c.buf.capacity() <= 10);
}

#[test]
fn four_gigabytes_announced_in_a_segmented_or_block_upload() {
    // The initiate response with size 0xFFFFFFFF: segmented (scs=2, s=1:
    // 0x41) and block (scs=6, s=1: 0xC2).
    for (method, answer) in [(Method::Auto, 0x41), (Method::Block, 0xC2)] {
        let mut c = client();
        c.upload_with(ms(0), 0x1F50, 1, method).unwrap();
        sent(&mut c);
        reply(
            &mut c,
            ms(1),
            [answer, 0x50, 0x1F, 0x01, 0xFF, 0xFF, 0xFF, 0xFF],
        );
        assert_eq!(
            one(&mut c),
            [0x80, 0x50, 0x1F, 0x01, 0x05, 0x00, 0x04, 0x05]
        );
        assert_eq!(
            events(&mut c),
            failed(0x1F50, 1, local(AbortCode::OutOfMemory))
        );
        assert_eq!(c.buf.capacity(), 0);
    }
}

#[test]
fn auto_method_follows_the_config() {
    let mut c = SdoClient::new(ClientConfig {
        block_download_above: Some(8),
        ..config()
    });
    let first_byte = |c: &mut SdoClient, data: &[u8]| {
        c.download(ms(0), 0x2000, 0, data).unwrap();
        let frame = one(c);
        c.abort(AbortCode::GeneralError);
        sent(c);
        events(c);
        frame[0]
    };
    assert_eq!(first_byte(&mut c, &[0; 4]), 0x23);
    assert_eq!(first_byte(&mut c, &[0; 8]), 0x21);
    assert_eq!(first_byte(&mut c, &[0; 9]), 0xC6);
    c.download_with(ms(0), 0x2000, 0, &[0; 9], Method::Standard)
        .unwrap();
    assert_eq!(one(&mut c)[0], 0x21);
}

#[test]
fn busy_while_a_transfer_runs() {
    let mut c = client();
    c.upload(ms(0), 0x1000, 0).unwrap();
    assert_eq!(c.upload(ms(0), 0x1001, 0), Err(Busy));
    assert_eq!(c.download(ms(0), 0x1001, 0, &[1]), Err(Busy));
    assert_eq!(one(&mut c), [0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]);
    reply(&mut c, ms(1), [0x43, 0x00, 0x10, 0x00, 1, 2, 3, 4]);
    assert!(c.is_idle());
    c.download(ms(2), 0x1001, 0, &[1]).unwrap();
    assert_eq!(one(&mut c), [0x2F, 0x01, 0x10, 0x00, 1, 0, 0, 0]);
    assert_eq!(events(&mut c).len(), 1);
}

#[test]
fn unpolled_events_are_bounded() {
    let mut c = client();
    for _ in 0..MAX_PENDING_EVENTS {
        c.upload(ms(0), 0x1000, 0).unwrap();
        c.abort(AbortCode::GeneralError);
    }
    assert!(c.is_idle());
    assert_eq!(c.upload(ms(0), 0x1000, 0), Err(Busy));
    assert_eq!(events(&mut c).len(), MAX_PENDING_EVENTS);
    c.upload(ms(0), 0x1000, 0).unwrap();
}

#[test]
fn local_abort() {
    let mut c = client();
    c.abort(AbortCode::GeneralError);
    assert!(sent(&mut c).is_empty() && events(&mut c).is_empty());
    c.download(ms(0), 0x2000, 5, b"a longer value").unwrap();
    sent(&mut c);
    c.abort(AbortCode::CannotTransfer);
    assert_eq!(
        one(&mut c),
        [0x80, 0x00, 0x20, 0x05, 0x20, 0x00, 0x00, 0x08]
    );
    assert_eq!(
        events(&mut c),
        failed(0x2000, 5, local(AbortCode::CannotTransfer))
    );
    assert!(c.is_idle());
    assert_eq!(c.poll_timeout(), None);
    // A late answer is ignored.
    reply(&mut c, ms(1), [0x60, 0x00, 0x20, 0x05, 0, 0, 0, 0]);
    assert!(sent(&mut c).is_empty() && events(&mut c).is_empty());
}

#[test]
fn download_buffer_does_not_outgrow_max_upload() {
    let mut c = SdoClient::new(ClientConfig {
        max_upload: 16,
        ..config()
    });
    c.download_with(ms(0), 0x2000, 0, &[7; 100], Method::Block)
        .unwrap();
    sent(&mut c);
    reply(
        &mut c,
        ms(1),
        [0x80, 0x00, 0x20, 0x00, 0x00, 0x00, 0x00, 0x08],
    );
    assert!(c.is_idle());
    assert!(c.buf.capacity() <= 16);
    // A small download reuses the buffer.
    c.download(ms(2), 0x2000, 0, &[1; 10]).unwrap();
    let capacity = c.buf.capacity();
    c.abort(AbortCode::GeneralError);
    assert_eq!(c.buf.capacity(), capacity);
}
