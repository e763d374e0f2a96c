//! Block download and block upload. Expected frames are written byte by
//! byte from the CiA 301 block-transfer layouts; the CRC is recomputed here
//! bit by bit (CRC-16 CCITT, polynomial 0x1021, initial value 0).

use alloc::vec::Vec;

use super::tests::{
    assert_idle, config, downloaded, drain, events, exchange, failed, server, store, uploaded,
};
use super::*;

/// CRC-16 of block transfers, one bit at a time.
fn crc16(data: &[u8]) -> u16 {
    let mut crc = 0u16;
    for &byte in data {
        crc ^= u16::from(byte) << 8;
        for _ in 0..8 {
            crc = if crc & 0x8000 != 0 {
                crc << 1 ^ 0x1021
            } else {
                crc << 1
            };
        }
    }
    crc
}

/// A block segment frame: `seq` (with bit 7 on the last) and 7 bytes of
/// `data` from `from` (zero past its end).
fn segment(seq: u8, last: bool, data: &[u8], from: usize) -> [u8; 8] {
    let mut frame = [0u8; 8];
    frame[0] = seq | if last { 0x80 } else { 0 };
    for (i, slot) in frame[1..].iter_mut().enumerate() {
        *slot = data.get(from + i).copied().unwrap_or(0);
    }
    frame
}

fn small_blocks() -> SdoServer<MemoryStore> {
    let mut config = config();
    config.block_size = 4;
    SdoServer::new(config, store())
}

#[test]
fn crc_helper_matches_the_check_value() {
    assert_eq!(crc16(b"123456789"), 0x31C3);
}

#[test]
fn block_download_with_a_gap_is_re_requested() {
    let data: Vec<u8> = (100..130).collect(); // 30 bytes: 5 segments, 5 unused.
    let mut s = small_blocks();
    // ccs=6, cc=1 (crc), s=1, cs=0: 0xC6; size 30.
    let out = exchange(&mut s, 0, [0xC6, 0x00, 0x20, 0x01, 30, 0, 0, 0]);
    // scs=5, sc=1, ss=0: 0xA4; blksize 4.
    assert_eq!(out, [[0xA4, 0x00, 0x20, 0x01, 4, 0, 0, 0]]);
    assert_eq!(s.poll_timeout(), Some(tests::at(500)));
    assert!(exchange(&mut s, 1, segment(1, false, &data, 0)).is_empty());
    assert!(exchange(&mut s, 2, segment(2, false, &data, 7)).is_empty());
    // Segment 3 is lost; 4 (the end of the sub-block) is ignored and the
    // server acknowledges 2 (0xA2, ackseq 2, blksize 4).
    let out = exchange(&mut s, 3, segment(4, false, &data, 21));
    assert_eq!(out, [[0xA2, 2, 4, 0, 0, 0, 0, 0]]);
    assert_eq!(s.poll_timeout(), Some(tests::at(503)));
    // The client resends from the third segment, numbered from 1 again.
    assert!(exchange(&mut s, 4, segment(1, false, &data, 14)).is_empty());
    assert!(exchange(&mut s, 5, segment(2, false, &data, 21)).is_empty());
    let out = exchange(&mut s, 6, segment(3, true, &data, 28));
    assert_eq!(out, [[0xA2, 3, 4, 0, 0, 0, 0, 0]]);
    assert!(events(&mut s).is_empty());
    // End: ccs=6, n=5, cs=1: 0xC0 | 5 << 2 | 1 = 0xD5, then the CRC.
    let [lo, hi] = crc16(&data).to_le_bytes();
    let out = exchange(&mut s, 7, [0xD5, lo, hi, 0, 0, 0, 0, 0]);
    assert_eq!(out, [[0xA1, 0, 0, 0, 0, 0, 0, 0]]);
    assert_eq!(s.store().get(0x2000, 1), Some(&data[..]));
    assert_eq!(events(&mut s), downloaded(0x2000, 1, 30));
    assert_idle(&s);
}

#[test]
fn block_download_gap_before_the_last_segment() {
    let data = b"0123456789";
    let mut s = small_blocks();
    // No CRC asked (0xC2): the server answers without it (0xA0).
    let out = exchange(&mut s, 0, [0xC2, 0x00, 0x20, 0x01, 10, 0, 0, 0]);
    assert_eq!(out, [[0xA0, 0x00, 0x20, 0x01, 4, 0, 0, 0]]);
    // Segment 1 is lost; the last one ends the sub-block: ack 0.
    let out = exchange(&mut s, 1, segment(2, true, data, 7));
    assert_eq!(out, [[0xA2, 0, 4, 0, 0, 0, 0, 0]]);
    assert!(exchange(&mut s, 2, segment(1, false, data, 0)).is_empty());
    let out = exchange(&mut s, 3, segment(2, true, data, 7));
    assert_eq!(out, [[0xA2, 2, 4, 0, 0, 0, 0, 0]]);
    // n=4; the CRC field is not checked without agreement.
    let out = exchange(&mut s, 4, [0xD1, 0xAA, 0xBB, 0, 0, 0, 0, 0]);
    assert_eq!(out, [[0xA1, 0, 0, 0, 0, 0, 0, 0]]);
    assert_eq!(s.store().get(0x2000, 1), Some(&data[..]));
}

#[test]
fn block_download_with_a_bad_crc_is_aborted() {
    let data = b"123456789";
    let mut s = server();
    let out = exchange(&mut s, 0, [0xC6, 0x00, 0x20, 0x01, 9, 0, 0, 0]);
    assert_eq!(out, [[0xA4, 0x00, 0x20, 0x01, 127, 0, 0, 0]]);
    assert!(exchange(&mut s, 1, segment(1, false, data, 0)).is_empty());
    let out = exchange(&mut s, 2, segment(2, true, data, 7));
    assert_eq!(out, [[0xA2, 2, 127, 0, 0, 0, 0, 0]]);
    // n=5: 0xD5; the right CRC would be C3 31.
    let out = exchange(&mut s, 3, [0xD5, 0xC3, 0x32, 0, 0, 0, 0, 0]);
    assert_eq!(out, [[0x80, 0x00, 0x20, 0x01, 0x04, 0x00, 0x04, 0x05]]);
    assert_eq!(
        events(&mut s),
        failed(0x2000, 1, SdoError::LocalAbort(AbortCode::CrcError))
    );
    assert_eq!(s.store().get(0x2000, 1), Some(&[][..]));
    assert!(s.is_idle());
}

#[test]
fn block_download_end_checks_the_size() {
    let data = b"123456789";
    let mut s = server();
    exchange(&mut s, 0, [0xC6, 0x00, 0x20, 0x01, 9, 0, 0, 0]);
    exchange(&mut s, 1, segment(1, false, data, 0));
    exchange(&mut s, 2, segment(2, true, data, 7));
    // n=6 leaves 8 bytes instead of the announced 9 (right CRC of those 8).
    let [lo, hi] = crc16(&data[..8]).to_le_bytes();
    let out = exchange(&mut s, 3, [0xD9, lo, hi, 0, 0, 0, 0, 0]);
    assert_eq!(out, [[0x80, 0x00, 0x20, 0x01, 0x13, 0x00, 0x07, 0x06]]);
    assert_eq!(
        events(&mut s),
        failed(0x2000, 1, SdoError::LocalAbort(AbortCode::LengthTooLow))
    );
}

#[test]
fn block_download_segments_past_the_size_are_refused() {
    let mut s = server();
    exchange(&mut s, 0, [0xC2, 0x00, 0x20, 0x01, 3, 0, 0, 0]);
    assert!(exchange(&mut s, 1, [0x01, 1, 2, 3, 0, 0, 0, 0]).is_empty());
    let out = exchange(&mut s, 2, [0x02, 1, 2, 3, 0, 0, 0, 0]);
    assert_eq!(out, [[0x80, 0x00, 0x20, 0x01, 0x12, 0x00, 0x07, 0x06]]);
    // Room for one segment (the allocator's minimum is 8 bytes).
    assert!(s.buffer_capacity() <= 8);
}

#[test]
fn abort_during_a_sub_block_is_not_a_segment() {
    let mut s = server();
    exchange(&mut s, 0, [0xC6, 0x00, 0x20, 0x01, 30, 0, 0, 0]);
    exchange(&mut s, 1, segment(1, false, &[0; 7], 0));
    let out = exchange(&mut s, 2, [0x80, 0x00, 0x20, 0x01, 0x00, 0x00, 0x00, 0x08]);
    assert!(out.is_empty());
    assert_eq!(
        events(&mut s),
        failed(0x2000, 1, SdoError::RemoteAbort(AbortCode::GeneralError))
    );
    assert!(s.is_idle());
}

#[test]
fn block_download_of_four_gigabytes_is_refused_before_allocating() {
    let mut s = server();
    let out = exchange(&mut s, 0, [0xC6, 0x00, 0x20, 0x01, 0xFF, 0xFF, 0xFF, 0xFF]);
    assert_eq!(out, [[0x80, 0x00, 0x20, 0x01, 0x05, 0x00, 0x04, 0x05]]);
    assert_eq!(
        events(&mut s),
        failed(0x2000, 1, SdoError::LocalAbort(AbortCode::OutOfMemory))
    );
    assert_eq!(s.buffer_capacity(), 0);
}

#[test]
fn block_download_timeout_in_a_sub_block() {
    let mut s = server();
    exchange(&mut s, 0, [0xC6, 0x00, 0x20, 0x01, 30, 0, 0, 0]);
    exchange(&mut s, 40, segment(1, false, &[0; 7], 0));
    s.handle_timeout(tests::at(540));
    assert_eq!(
        drain(&mut s),
        [[0x80, 0x00, 0x20, 0x01, 0x00, 0x00, 0x04, 0x05]]
    );
    assert_eq!(events(&mut s), failed(0x2000, 1, SdoError::Timeout));
    assert!(s.is_idle());
}

#[test]
fn block_upload_with_a_short_ack_resends() {
    let data: Vec<u8> = (0..20).collect(); // 3 segments, 1 unused byte.
    let mut s = server();
    // ccs=5, cc=1, cs=0: 0xA4; blksize 2, pst 0.
    let out = exchange(&mut s, 0, [0xA4, 0x00, 0x20, 0x02, 2, 0, 0, 0]);
    // scs=6, sc=1, s=1, ss=0: 0xC6; size 20.
    assert_eq!(out, [[0xC6, 0x00, 0x20, 0x02, 20, 0, 0, 0]]);
    // Start (0xA3): the first sub-block of 2 segments.
    let out = exchange(&mut s, 1, [0xA3, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(
        out,
        [segment(1, false, &data, 0), segment(2, false, &data, 7)]
    );
    assert_eq!(s.poll_timeout(), Some(tests::at(501)));
    // The client got only the first: ackseq 1, blksize 2.
    let out = exchange(&mut s, 2, [0xA2, 1, 2, 0, 0, 0, 0, 0]);
    assert_eq!(
        out,
        [segment(1, false, &data, 7), segment(2, true, &data, 14)]
    );
    assert!(events(&mut s).is_empty());
    // Everything acknowledged: end with n=1 (0xC5) and the CRC.
    let out = exchange(&mut s, 3, [0xA2, 2, 2, 0, 0, 0, 0, 0]);
    let [lo, hi] = crc16(&data).to_le_bytes();
    assert_eq!(out, [[0xC5, lo, hi, 0, 0, 0, 0, 0]]);
    assert!(events(&mut s).is_empty());
    // The client's end (0xA1) completes the upload.
    assert!(exchange(&mut s, 4, [0xA1, 0, 0, 0, 0, 0, 0, 0]).is_empty());
    assert_eq!(events(&mut s), uploaded(0x2000, 2, 20));
    assert_idle(&s);
}

#[test]
fn block_upload_takes_the_new_block_size_from_the_ack() {
    let data = b"ABCDEFGHIJ";
    let mut s = server();
    // No CRC asked (0xA0): answered without (0xC2), end CRC zero.
    let out = exchange(&mut s, 0, [0xA0, 0x08, 0x10, 0x00, 1, 0, 0, 0]);
    assert_eq!(out, [[0xC2, 0x08, 0x10, 0x00, 10, 0, 0, 0]]);
    let out = exchange(&mut s, 1, [0xA3, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(out, [segment(1, false, data, 0)]);
    let out = exchange(&mut s, 2, [0xA2, 1, 127, 0, 0, 0, 0, 0]);
    assert_eq!(out, [segment(1, true, data, 7)]);
    // n=4: 0xD1.
    let out = exchange(&mut s, 3, [0xA2, 1, 127, 0, 0, 0, 0, 0]);
    assert_eq!(out, [[0xD1, 0, 0, 0, 0, 0, 0, 0]]);
}

#[test]
fn block_upload_of_an_empty_value() {
    let mut s = server();
    let out = exchange(&mut s, 0, [0xA4, 0x00, 0x20, 0x01, 4, 0, 0, 0]);
    assert_eq!(out, [[0xC6, 0x00, 0x20, 0x01, 0, 0, 0, 0]]);
    let out = exchange(&mut s, 1, [0xA3, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(out, [[0x81, 0, 0, 0, 0, 0, 0, 0]]);
    // n=7: 0xDD; CRC of nothing is 0.
    let out = exchange(&mut s, 2, [0xA2, 1, 4, 0, 0, 0, 0, 0]);
    assert_eq!(out, [[0xDD, 0, 0, 0, 0, 0, 0, 0]]);
}

#[test]
fn block_upload_refuses_bad_block_sizes_and_sequence_numbers() {
    let mut s = server();
    for blksize in [0u8, 128] {
        let out = exchange(&mut s, 0, [0xA4, 0x00, 0x20, 0x02, blksize, 0, 0, 0]);
        assert_eq!(out, [[0x80, 0x00, 0x20, 0x02, 0x02, 0x00, 0x04, 0x05]]);
        assert_eq!(
            events(&mut s),
            failed(0x2000, 2, SdoError::LocalAbort(AbortCode::InvalidBlockSize))
        );
    }
    // An ack of a segment never sent: invalid sequence number.
    exchange(&mut s, 1, [0xA4, 0x00, 0x20, 0x02, 2, 0, 0, 0]);
    exchange(&mut s, 2, [0xA3, 0, 0, 0, 0, 0, 0, 0]);
    let out = exchange(&mut s, 3, [0xA2, 3, 2, 0, 0, 0, 0, 0]);
    assert_eq!(out, [[0x80, 0x00, 0x20, 0x02, 0x03, 0x00, 0x04, 0x05]]);
    // An ack before the start: invalid command.
    exchange(&mut s, 4, [0xA4, 0x00, 0x20, 0x02, 2, 0, 0, 0]);
    let out = exchange(&mut s, 5, [0xA2, 1, 2, 0, 0, 0, 0, 0]);
    assert_eq!(out, [[0x80, 0x00, 0x20, 0x02, 0x01, 0x00, 0x04, 0x05]]);
    // A bad block size in an ack.
    exchange(&mut s, 6, [0xA4, 0x00, 0x20, 0x02, 2, 0, 0, 0]);
    exchange(&mut s, 7, [0xA3, 0, 0, 0, 0, 0, 0, 0]);
    let out = exchange(&mut s, 8, [0xA2, 2, 0, 0, 0, 0, 0, 0]);
    assert_eq!(out, [[0x80, 0x00, 0x20, 0x02, 0x02, 0x00, 0x04, 0x05]]);
}

#[test]
fn block_upload_timeout_waiting_for_the_ack() {
    let mut s = server();
    exchange(&mut s, 0, [0xA4, 0x00, 0x20, 0x02, 127, 0, 0, 0]);
    let out = exchange(&mut s, 10, [0xA3, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(out.len(), 3);
    assert_eq!(s.poll_timeout(), Some(tests::at(510)));
    s.handle_timeout(tests::at(510));
    assert_eq!(
        drain(&mut s),
        [[0x80, 0x00, 0x20, 0x02, 0x00, 0x00, 0x04, 0x05]]
    );
    assert_eq!(events(&mut s), failed(0x2000, 2, SdoError::Timeout));
    assert!(s.is_idle());
}

#[test]
fn client_abort_during_a_block_upload() {
    let mut s = server();
    exchange(&mut s, 0, [0xA4, 0x00, 0x20, 0x02, 127, 0, 0, 0]);
    exchange(&mut s, 1, [0xA3, 0, 0, 0, 0, 0, 0, 0]);
    let out = exchange(&mut s, 2, [0x80, 0x00, 0x20, 0x02, 0x05, 0x00, 0x04, 0x05]);
    assert!(out.is_empty());
    assert_eq!(
        events(&mut s),
        failed(0x2000, 2, SdoError::RemoteAbort(AbortCode::OutOfMemory))
    );
}
