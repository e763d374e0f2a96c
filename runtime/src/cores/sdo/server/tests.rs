//! Expedited and segmented transfers, aborts, timeouts. Expected frames are
//! written byte by byte from the CiA 301 SDO frame layouts.

use alloc::vec::Vec;
use core::time::Duration;

use super::*;
use crate::CanId;
use crate::od::{AccessRight, NodeId};

/// Request and response COB-IDs of node 1.
const REQ: u16 = 0x601;
const RESP: u16 = 0x581;

pub(super) fn config() -> ServerConfig {
    let node = NodeId::new(1).unwrap();
    ServerConfig::new(Channel::default_for(node))
}

pub(super) fn store() -> MemoryStore {
    let mut store = MemoryStore::new();
    store.insert_fixed(0x1000, 0, AccessRight::Ro, &[0x92, 0x01, 0x02, 0x00]);
    store.insert(0x1008, 0, AccessRight::Const, b"ABCDEFGHIJ");
    store.insert_fixed(0x1017, 0, AccessRight::Rw, &[0xE8, 0x03]);
    store.insert(0x2000, 1, AccessRight::Rw, &[]);
    store.insert(0x2000, 2, AccessRight::Ro, &(0..20).collect::<Vec<u8>>());
    store.insert(0x2001, 0, AccessRight::Wo, &[0]);
    store
}

pub(super) fn server() -> SdoServer<MemoryStore> {
    SdoServer::new(config(), store())
}

pub(super) fn at(ms: u64) -> Instant {
    Instant::from_millis(ms)
}

/// Feeds one client frame at `ms` and returns every frame the server sends
/// in reply (checking their identifier and length).
pub(super) fn exchange(
    server: &mut SdoServer<MemoryStore>,
    ms: u64,
    data: [u8; 8],
) -> Vec<[u8; 8]> {
    server.handle_frame(at(ms), &Frame::standard(REQ, data, 8));
    drain(server)
}

pub(super) fn drain(server: &mut SdoServer<MemoryStore>) -> Vec<[u8; 8]> {
    let mut out = Vec::new();
    while let Some(frame) = server.poll_transmit() {
        assert_eq!(frame.id(), CanId::Standard(RESP));
        assert_eq!(frame.len(), 8);
        out.push(*frame.data_padded());
    }
    out
}

pub(super) fn events(server: &mut SdoServer<MemoryStore>) -> Vec<ServerEvent> {
    core::iter::from_fn(|| server.poll_event()).collect()
}

pub(super) fn failed(index: u16, sub: u8, error: SdoError) -> Vec<ServerEvent> {
    vec![ServerEvent::Failed { index, sub, error }]
}

pub(super) fn downloaded(index: u16, sub: u8, len: usize) -> Vec<ServerEvent> {
    vec![ServerEvent::Downloaded { index, sub, len }]
}

pub(super) fn uploaded(index: u16, sub: u8, len: usize) -> Vec<ServerEvent> {
    vec![ServerEvent::Uploaded { index, sub, len }]
}

/// The server is idle, waiting for nothing.
pub(super) fn assert_idle(server: &SdoServer<MemoryStore>) {
    assert!(server.is_idle());
    assert_eq!(server.poll_timeout(), None);
}

#[test]
fn expedited_upload_of_four_bytes() {
    let mut s = server();
    let out = exchange(&mut s, 0, [0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]);
    assert_eq!(out, [[0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00]]);
    assert_eq!(events(&mut s), uploaded(0x1000, 0, 4));
    assert_idle(&s);
}

#[test]
fn expedited_download_of_two_bytes() {
    let mut s = server();
    // ccs=1, n=2, e=1, s=1: 0x2B.
    let out = exchange(&mut s, 0, [0x2B, 0x17, 0x10, 0x00, 0xD0, 0x07, 0, 0]);
    assert_eq!(out, [[0x60, 0x17, 0x10, 0x00, 0, 0, 0, 0]]);
    assert_eq!(s.store().get(0x1017, 0), Some(&[0xD0, 0x07][..]));
    assert_eq!(events(&mut s), downloaded(0x1017, 0, 2));
}

#[test]
fn segmented_download_of_ten_bytes() {
    let mut s = server();
    // Initiate, size indicated (s=1, e=0): 0x21, size 10.
    let out = exchange(&mut s, 0, [0x21, 0x00, 0x20, 0x01, 10, 0, 0, 0]);
    assert_eq!(out, [[0x60, 0x00, 0x20, 0x01, 0, 0, 0, 0]]);
    assert!(!s.is_idle());
    assert_eq!(s.poll_timeout(), Some(at(500)));
    // Toggle 0, 7 bytes (n=0), more to come: 0x00. Answer 0x20 (t=0).
    let out = exchange(&mut s, 10, [0x00, b'A', b'B', b'C', b'D', b'E', b'F', b'G']);
    assert_eq!(out, [[0x20, 0, 0, 0, 0, 0, 0, 0]]);
    assert_eq!(s.poll_timeout(), Some(at(510)));
    assert!(events(&mut s).is_empty());
    // Toggle 1, 3 bytes (n=4), last: 0x10 | 4 << 1 | 1 = 0x19. Answer 0x30.
    let out = exchange(&mut s, 20, [0x19, b'H', b'I', b'J', 0, 0, 0, 0]);
    assert_eq!(out, [[0x30, 0, 0, 0, 0, 0, 0, 0]]);
    assert_eq!(s.store().get(0x2000, 1), Some(&b"ABCDEFGHIJ"[..]));
    assert_eq!(events(&mut s), downloaded(0x2000, 1, 10));
    assert_idle(&s);
}

#[test]
fn segmented_upload_of_ten_bytes() {
    let mut s = server();
    let out = exchange(&mut s, 0, [0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0]);
    assert_eq!(out, [[0x41, 0x08, 0x10, 0x00, 10, 0, 0, 0]]);
    let out = exchange(&mut s, 1, [0x60, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(out, [[0x00, b'A', b'B', b'C', b'D', b'E', b'F', b'G']]);
    assert!(events(&mut s).is_empty());
    let out = exchange(&mut s, 2, [0x70, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(out, [[0x19, b'H', b'I', b'J', 0, 0, 0, 0]]);
    assert_eq!(events(&mut s), uploaded(0x1008, 0, 10));
    assert!(s.is_idle());
}

#[test]
fn empty_value_uploads_as_one_empty_segment() {
    let mut s = server();
    let out = exchange(&mut s, 0, [0x40, 0x00, 0x20, 0x01, 0, 0, 0, 0]);
    assert_eq!(out, [[0x41, 0x00, 0x20, 0x01, 0, 0, 0, 0]]);
    // t=0, n=7, c=1: 0x0F.
    let out = exchange(&mut s, 1, [0x60, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(out, [[0x0F, 0, 0, 0, 0, 0, 0, 0]]);
    assert_eq!(events(&mut s), uploaded(0x2000, 1, 0));
}

#[test]
fn wrong_toggle_aborts_downloads_and_uploads() {
    let mut s = server();
    exchange(&mut s, 0, [0x21, 0x00, 0x20, 0x01, 10, 0, 0, 0]);
    let out = exchange(&mut s, 1, [0x10, 1, 2, 3, 4, 5, 6, 7]);
    assert_eq!(out, [[0x80, 0x00, 0x20, 0x01, 0x00, 0x00, 0x03, 0x05]]);
    assert_eq!(
        events(&mut s),
        failed(
            0x2000,
            1,
            SdoError::LocalAbort(AbortCode::ToggleBitNotAlternated)
        )
    );
    assert_idle(&s);

    exchange(&mut s, 2, [0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0]);
    exchange(&mut s, 3, [0x60, 0, 0, 0, 0, 0, 0, 0]);
    // The second segment request must carry toggle 1.
    let out = exchange(&mut s, 4, [0x60, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(out, [[0x80, 0x08, 0x10, 0x00, 0x00, 0x00, 0x03, 0x05]]);
    assert_eq!(
        events(&mut s),
        failed(
            0x1008,
            0,
            SdoError::LocalAbort(AbortCode::ToggleBitNotAlternated)
        )
    );
}

#[test]
fn store_errors_are_sent_as_aborts() {
    let mut s = server();
    // Write of a read-only object: 0x06010002.
    let out = exchange(&mut s, 0, [0x23, 0x00, 0x10, 0x00, 1, 2, 3, 4]);
    assert_eq!(out, [[0x80, 0x00, 0x10, 0x00, 0x02, 0x00, 0x01, 0x06]]);
    assert_eq!(
        events(&mut s),
        failed(0x1000, 0, SdoError::LocalAbort(AbortCode::WriteReadOnly))
    );
    // Read of a write-only object: 0x06010001.
    let out = exchange(&mut s, 1, [0x40, 0x01, 0x20, 0x00, 0, 0, 0, 0]);
    assert_eq!(out, [[0x80, 0x01, 0x20, 0x00, 0x01, 0x00, 0x01, 0x06]]);
    // Missing object: 0x06020000; missing sub-index: 0x06090011.
    let out = exchange(&mut s, 2, [0x40, 0x00, 0x30, 0x00, 0, 0, 0, 0]);
    assert_eq!(out, [[0x80, 0x00, 0x30, 0x00, 0x00, 0x00, 0x02, 0x06]]);
    let out = exchange(&mut s, 3, [0x21, 0x00, 0x20, 0x07, 10, 0, 0, 0]);
    assert_eq!(out, [[0x80, 0x00, 0x20, 0x07, 0x11, 0x00, 0x09, 0x06]]);
    // A 4-byte expedited write of a 2-byte value: length too high.
    let out = exchange(&mut s, 4, [0x23, 0x17, 0x10, 0x00, 1, 2, 3, 4]);
    assert_eq!(out, [[0x80, 0x17, 0x10, 0x00, 0x12, 0x00, 0x07, 0x06]]);
    events(&mut s);
    // Unannounced size: the store refuses the complete value at the end.
    exchange(&mut s, 5, [0x20, 0x17, 0x10, 0x00, 0, 0, 0, 0]);
    let out = exchange(&mut s, 6, [0x09, 1, 2, 3, 0, 0, 0, 0]);
    assert_eq!(out, [[0x80, 0x17, 0x10, 0x00, 0x12, 0x00, 0x07, 0x06]]);
    assert_eq!(
        events(&mut s),
        failed(0x1017, 0, SdoError::LocalAbort(AbortCode::LengthTooHigh))
    );
    assert_eq!(s.store().get(0x1017, 0), Some(&[0xE8, 0x03][..]));
    assert!(s.is_idle());
}

#[test]
fn data_length_must_match_the_announced_size() {
    let mut s = server();
    // Size 10, but the last segment comes after 7 bytes: too low.
    exchange(&mut s, 0, [0x21, 0x00, 0x20, 0x01, 10, 0, 0, 0]);
    let out = exchange(&mut s, 1, [0x01, 1, 2, 3, 4, 5, 6, 7]);
    assert_eq!(out, [[0x80, 0x00, 0x20, 0x01, 0x13, 0x00, 0x07, 0x06]]);
    assert_eq!(
        events(&mut s),
        failed(0x2000, 1, SdoError::LocalAbort(AbortCode::LengthTooLow))
    );
    // Size 3, but a segment carries 7 bytes: too high, refused at once.
    exchange(&mut s, 2, [0x21, 0x00, 0x20, 0x01, 3, 0, 0, 0]);
    let out = exchange(&mut s, 3, [0x00, 1, 2, 3, 4, 5, 6, 7]);
    assert_eq!(out, [[0x80, 0x00, 0x20, 0x01, 0x12, 0x00, 0x07, 0x06]]);
    assert_eq!(s.store().get(0x2000, 1), Some(&[][..]));
}

#[test]
fn unknown_and_unexpected_requests_are_refused() {
    let mut s = server();
    // ccs=7 does not exist.
    let out = exchange(&mut s, 0, [0xE0, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(out, [[0x80, 0, 0, 0, 0x01, 0x00, 0x04, 0x05]]);
    // A segment with no transfer running.
    let out = exchange(&mut s, 1, [0x60, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(out, [[0x80, 0, 0, 0, 0x01, 0x00, 0x04, 0x05]]);
    // Nothing ended: no events.
    assert!(events(&mut s).is_empty());
    // An upload segment request in the middle of a download.
    exchange(&mut s, 2, [0x21, 0x00, 0x20, 0x01, 10, 0, 0, 0]);
    let out = exchange(&mut s, 3, [0x60, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(out, [[0x80, 0x00, 0x20, 0x01, 0x01, 0x00, 0x04, 0x05]]);
    assert_eq!(
        events(&mut s),
        failed(0x2000, 1, SdoError::LocalAbort(AbortCode::InvalidCommand))
    );
    // A short frame while a transfer runs.
    exchange(&mut s, 4, [0x21, 0x00, 0x20, 0x01, 10, 0, 0, 0]);
    let short = Frame::new(CanId::Standard(REQ), &[0x00, 1, 2]).unwrap();
    s.handle_frame(at(5), &short);
    assert_eq!(
        drain(&mut s),
        [[0x80, 0x00, 0x20, 0x01, 0x01, 0x00, 0x04, 0x05]]
    );
    assert!(s.is_idle());
}

#[test]
fn frames_that_are_not_requests_are_ignored() {
    let mut s = server();
    let data = [0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0];
    s.handle_frame(at(0), &Frame::standard(RESP, data, 8));
    s.handle_frame(at(0), &Frame::standard(0x602, data, 8));
    s.handle_frame(
        at(0),
        &Frame::new(CanId::Extended(REQ as u32), &data).unwrap(),
    );
    s.handle_frame(at(0), &Frame::remote(CanId::Standard(REQ), 8).unwrap());
    assert!(drain(&mut s).is_empty());
    assert!(events(&mut s).is_empty());
    assert!(s.is_idle());
}

#[test]
fn timeout_sends_the_timeout_abort() {
    let mut s = server();
    exchange(&mut s, 0, [0x21, 0x00, 0x20, 0x01, 10, 0, 0, 0]);
    exchange(&mut s, 100, [0x00, 1, 2, 3, 4, 5, 6, 7]);
    assert_eq!(s.poll_timeout(), Some(at(600)));
    s.handle_timeout(at(599));
    assert!(drain(&mut s).is_empty());
    assert!(!s.is_idle());
    s.handle_timeout(at(600));
    assert_eq!(
        drain(&mut s),
        [[0x80, 0x00, 0x20, 0x01, 0x00, 0x00, 0x04, 0x05]]
    );
    assert_eq!(events(&mut s), failed(0x2000, 1, SdoError::Timeout));
    assert_idle(&s);
    // Later timeouts do nothing.
    s.handle_timeout(at(2000));
    assert!(drain(&mut s).is_empty());
}

#[test]
fn configured_timeout_is_used() {
    let mut config = config();
    config.timeout = Duration::from_millis(20);
    let mut s = SdoServer::new(config, store());
    exchange(&mut s, 5, [0x40, 0x08, 0x10, 0x00, 0, 0, 0, 0]);
    assert_eq!(s.poll_timeout(), Some(at(25)));
}

#[test]
fn client_abort_ends_the_transfer_silently() {
    let mut s = server();
    exchange(&mut s, 0, [0x21, 0x00, 0x20, 0x01, 10, 0, 0, 0]);
    let out = exchange(&mut s, 1, [0x80, 0x00, 0x20, 0x01, 0x00, 0x00, 0x00, 0x08]);
    assert!(out.is_empty());
    assert_eq!(
        events(&mut s),
        failed(0x2000, 1, SdoError::RemoteAbort(AbortCode::GeneralError))
    );
    assert_idle(&s);
    // An abort with no transfer running is not answered.
    let out = exchange(&mut s, 2, [0x80, 0x00, 0x20, 0x01, 0x00, 0x00, 0x00, 0x08]);
    assert!(out.is_empty());
    assert!(events(&mut s).is_empty());
}

#[test]
fn a_new_initiate_restarts_without_an_abort() {
    let mut s = server();
    exchange(&mut s, 0, [0x21, 0x00, 0x20, 0x01, 10, 0, 0, 0]);
    exchange(&mut s, 1, [0x00, 1, 2, 3, 4, 5, 6, 7]);
    // The client starts over with an upload: served, the download dropped.
    let out = exchange(&mut s, 2, [0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]);
    assert_eq!(out, [[0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00]]);
    assert_eq!(events(&mut s), uploaded(0x1000, 0, 4));
    assert_eq!(s.store().get(0x2000, 1), Some(&[][..]));
    // And a download restarted from its initiate starts from zero bytes.
    exchange(&mut s, 3, [0x21, 0x00, 0x20, 0x01, 3, 0, 0, 0]);
    exchange(&mut s, 4, [0x00, 9, 9, 9, 9, 9, 9, 9]);
    exchange(&mut s, 5, [0x21, 0x00, 0x20, 0x01, 3, 0, 0, 0]);
    let out = exchange(&mut s, 6, [0x09, 7, 8, 9, 0, 0, 0, 0]);
    assert_eq!(out, [[0x20, 0, 0, 0, 0, 0, 0, 0]]);
    assert_eq!(s.store().get(0x2000, 1), Some(&[7, 8, 9][..]));
}

#[test]
fn four_gigabytes_announced_is_refused_before_allocating() {
    let mut s = server();
    let out = exchange(&mut s, 0, [0x21, 0x00, 0x20, 0x01, 0xFF, 0xFF, 0xFF, 0xFF]);
    assert_eq!(out, [[0x80, 0x00, 0x20, 0x01, 0x05, 0x00, 0x04, 0x05]]);
    assert_eq!(
        events(&mut s),
        failed(0x2000, 1, SdoError::LocalAbort(AbortCode::OutOfMemory))
    );
    assert_eq!(s.buffer_capacity(), 0);
    assert!(s.is_idle());
}

#[test]
fn unannounced_data_past_the_bound_is_refused() {
    let mut config = config();
    config.max_download = 10;
    let mut s = SdoServer::new(config, store());
    exchange(&mut s, 0, [0x20, 0x00, 0x20, 0x01, 0, 0, 0, 0]);
    exchange(&mut s, 1, [0x00, 1, 2, 3, 4, 5, 6, 7]);
    let out = exchange(&mut s, 2, [0x10, 1, 2, 3, 4, 5, 6, 7]);
    assert_eq!(out, [[0x80, 0x00, 0x20, 0x01, 0x05, 0x00, 0x04, 0x05]]);
    assert_eq!(
        events(&mut s),
        failed(0x2000, 1, SdoError::LocalAbort(AbortCode::OutOfMemory))
    );
    assert!(s.buffer_capacity() <= 14);
    // An announced size of 11 is refused at once.
    let out = exchange(&mut s, 3, [0x21, 0x00, 0x20, 0x01, 11, 0, 0, 0]);
    assert_eq!(out, [[0x80, 0x00, 0x20, 0x01, 0x05, 0x00, 0x04, 0x05]]);
}

#[test]
fn the_buffer_is_reused_across_transfers() {
    let mut s = server();
    for round in 0..3u64 {
        exchange(&mut s, round * 10, [0x21, 0x00, 0x20, 0x01, 10, 0, 0, 0]);
        exchange(&mut s, round * 10 + 1, [0x00, 1, 2, 3, 4, 5, 6, 7]);
        exchange(&mut s, round * 10 + 2, [0x19, 8, 9, 10, 0, 0, 0, 0]);
        assert_eq!(s.buffer_capacity(), 10);
    }
    assert_eq!(
        s.into_store().get(0x2000, 1),
        Some(&[1, 2, 3, 4, 5, 6, 7, 8, 9, 10][..])
    );
}

#[test]
fn unannounced_downloads_keep_the_buffer_within_the_bound() {
    let mut config = config();
    config.max_download = 100;
    let mut s = SdoServer::new(config, store());
    exchange(&mut s, 0, [0x20, 0x00, 0x20, 0x01, 0, 0, 0, 0]);
    let mut toggle = 0u8;
    for ms in 1..=14 {
        let out = exchange(&mut s, ms, [toggle, 1, 2, 3, 4, 5, 6, 7]);
        assert_eq!(out, [[0x20 | toggle, 0, 0, 0, 0, 0, 0, 0]]);
        toggle ^= 0x10;
        assert!(s.buffer_capacity() <= 100);
    }
    // 98 bytes so far; 2 more fit exactly: t, n=5, c=1.
    let out = exchange(&mut s, 15, [toggle | 0x0B, 1, 2, 0, 0, 0, 0, 0]);
    assert_eq!(out, [[0x20 | toggle, 0, 0, 0, 0, 0, 0, 0]]);
    assert_eq!(s.store().get(0x2000, 1).map(<[u8]>::len), Some(100));
    assert!(s.buffer_capacity() <= 100);
}
