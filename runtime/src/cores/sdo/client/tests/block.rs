//! Block download and block upload, frames written from the CiA 301 block
//! protocol layouts.

use super::*;

#[test]
fn block_download_of_twenty_bytes_with_a_resend() {
    let data: Vec<u8> = (1..=20).collect();
    let mut c = client();
    c.download_with(ms(0), 0x1F50, 1, &data, Method::Block)
        .unwrap();
    // ccs=6, cc=1 (CRC), s=1, cs=0; size 20.
    assert_eq!(one(&mut c), [0xC6, 0x50, 0x1F, 0x01, 20, 0, 0, 0]);
    // scs=5, sc=1 (CRC), block size 2.
    reply(&mut c, ms(1), [0xA4, 0x50, 0x1F, 0x01, 2, 0, 0, 0]);
    assert_eq!(c.poll_timeout(), None, "segments to send: no wait");
    assert_eq!(
        sent(&mut c),
        [
            [0x01, 1, 2, 3, 4, 5, 6, 7],
            [0x02, 8, 9, 10, 11, 12, 13, 14]
        ]
    );
    assert_eq!(c.poll_timeout(), Some(ms(501)));
    // The server got only segment 1 and keeps block size 2.
    reply(&mut c, ms(2), [0xA2, 1, 2, 0, 0, 0, 0, 0]);
    assert_eq!(
        sent(&mut c),
        [
            [0x01, 8, 9, 10, 11, 12, 13, 14],
            [0x82, 15, 16, 17, 18, 19, 20, 0]
        ]
    );
    reply(&mut c, ms(3), [0xA2, 2, 2, 0, 0, 0, 0, 0]);
    // ccs=6, n=1 unused byte, cs=1: 0xC1 | 1 << 2; CRC little-endian.
    let [lo, hi] = crc16_xmodem(&data).to_le_bytes();
    assert_eq!(one(&mut c), [0xC5, lo, hi, 0, 0, 0, 0, 0]);
    assert_eq!(c.poll_timeout(), Some(ms(503)));
    reply(&mut c, ms(4), [0xA1, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(
        events(&mut c),
        vec![ClientEvent::Downloaded {
            index: 0x1F50,
            sub: 1
        }]
    );
    assert!(c.is_idle());
}

#[test]
fn block_download_without_server_crc() {
    let mut c = client();
    c.download_with(ms(0), 0x2000, 0, b"abc", Method::Block)
        .unwrap();
    sent(&mut c);
    reply(&mut c, ms(1), [0xA0, 0x00, 0x20, 0x00, 127, 0, 0, 0]);
    assert_eq!(one(&mut c), [0x81, b'a', b'b', b'c', 0, 0, 0, 0]);
    reply(&mut c, ms(2), [0xA2, 1, 127, 0, 0, 0, 0, 0]);
    // n=4 unused bytes, no CRC: 0xC1 | 4 << 2.
    assert_eq!(one(&mut c), [0xD1, 0, 0, 0, 0, 0, 0, 0]);
}

#[test]
fn block_download_rejects_bad_block_sizes_and_acks() {
    let invalid_size = [0x80, 0x00, 0x20, 0x00, 0x02, 0x00, 0x04, 0x05];
    let data = [0x55; 30];
    // Block size 128 in the initiate response.
    let mut c = client();
    c.download_with(ms(0), 0x2000, 0, &data, Method::Block)
        .unwrap();
    sent(&mut c);
    reply(&mut c, ms(1), [0xA4, 0x00, 0x20, 0x00, 128, 0, 0, 0]);
    assert_eq!(one(&mut c), invalid_size);
    // Block size 0 in an ack.
    c.download_with(ms(2), 0x2000, 0, &data, Method::Block)
        .unwrap();
    sent(&mut c);
    reply(&mut c, ms(3), [0xA4, 0x00, 0x20, 0x00, 2, 0, 0, 0]);
    assert_eq!(sent(&mut c).len(), 2);
    reply(&mut c, ms(4), [0xA2, 2, 0, 0, 0, 0, 0, 0]);
    assert_eq!(one(&mut c), invalid_size);
    assert_eq!(
        events(&mut c),
        [
            failed(0x2000, 0, local(AbortCode::InvalidBlockSize)),
            failed(0x2000, 0, local(AbortCode::InvalidBlockSize)),
        ]
        .concat()
    );
    // An ack of more segments than were sent.
    c.download_with(ms(5), 0x2000, 0, &data, Method::Block)
        .unwrap();
    sent(&mut c);
    reply(&mut c, ms(6), [0xA4, 0x00, 0x20, 0x00, 2, 0, 0, 0]);
    sent(&mut c);
    reply(&mut c, ms(7), [0xA2, 3, 2, 0, 0, 0, 0, 0]);
    assert_eq!(
        one(&mut c),
        [0x80, 0x00, 0x20, 0x00, 0x03, 0x00, 0x04, 0x05]
    );
}

#[test]
fn block_download_times_out_only_after_its_segments() {
    let mut c = client();
    c.download_with(ms(0), 0x2000, 0, &[0; 14], Method::Block)
        .unwrap();
    sent(&mut c);
    reply(&mut c, ms(1), [0xA4, 0x00, 0x20, 0x00, 127, 0, 0, 0]);
    assert_eq!(c.poll_timeout(), None);
    c.handle_timeout(ms(10_000));
    assert!(events(&mut c).is_empty());
    assert_eq!(sent(&mut c).len(), 2);
    assert_eq!(c.poll_timeout(), Some(ms(501)));
    c.handle_timeout(ms(501));
    assert_eq!(
        one(&mut c),
        [0x80, 0x00, 0x20, 0x00, 0x00, 0x00, 0x04, 0x05]
    );
    assert_eq!(events(&mut c), failed(0x2000, 0, SdoError::Timeout));
}

#[test]
fn block_upload_with_a_lost_segment() {
    let data = b"CANopen block upload test";
    assert_eq!(data.len(), 25);
    let segment = |n: usize| {
        let mut bytes = [0u8; 7];
        let chunk = &data[7 * n..data.len().min(7 * n + 7)];
        bytes[..chunk.len()].copy_from_slice(chunk);
        bytes
    };
    let frame = |first: u8, n: usize| {
        let mut bytes = [first, 0, 0, 0, 0, 0, 0, 0];
        bytes[1..].copy_from_slice(&segment(n));
        bytes
    };
    let mut c = SdoClient::new(ClientConfig {
        block_size: 4,
        ..config()
    });
    c.upload_with(ms(0), 0x1F50, 1, Method::Block).unwrap();
    // ccs=5, cc=1 (CRC), cs=0; block size 4, pst 0.
    assert_eq!(one(&mut c), [0xA4, 0x50, 0x1F, 0x01, 4, 0, 0, 0]);
    // scs=6, sc=1, s=1, ss=0; size 25.
    reply(&mut c, ms(1), [0xC6, 0x50, 0x1F, 0x01, 25, 0, 0, 0]);
    assert_eq!(one(&mut c), [0xA3, 0, 0, 0, 0, 0, 0, 0]);
    reply(&mut c, ms(2), frame(0x01, 0));
    // Segment 2 is lost; 3 and the last one (4) arrive.
    reply(&mut c, ms(3), frame(0x03, 2));
    assert!(sent(&mut c).is_empty());
    reply(&mut c, ms(4), frame(0x84, 3));
    // Ack of segment 1, block size 4.
    assert_eq!(one(&mut c), [0xA2, 1, 4, 0, 0, 0, 0, 0]);
    // The server resends from segment 2 in a new sub-block.
    reply(&mut c, ms(5), frame(0x01, 1));
    reply(&mut c, ms(6), frame(0x02, 2));
    reply(&mut c, ms(7), frame(0x83, 3));
    assert_eq!(one(&mut c), [0xA2, 3, 4, 0, 0, 0, 0, 0]);
    assert_eq!(c.poll_timeout(), Some(ms(507)));
    // scs=6, n=3 unused bytes, ss=1: 0xC1 | 3 << 2.
    let [lo, hi] = crc16_xmodem(data).to_le_bytes();
    reply(&mut c, ms(8), [0xCD, lo, hi, 0, 0, 0, 0, 0]);
    assert_eq!(one(&mut c), [0xA1, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(
        events(&mut c),
        vec![ClientEvent::Uploaded {
            index: 0x1F50,
            sub: 1,
            data: data.to_vec(),
            padded: false
        }]
    );
    assert!(c.is_idle());
}

#[test]
fn block_upload_over_several_sub_blocks_without_size() {
    let mut c = SdoClient::new(ClientConfig {
        block_size: 2,
        crc: false,
        ..config()
    });
    c.upload_with(ms(0), 0x2000, 0, Method::Block).unwrap();
    assert_eq!(one(&mut c), [0xA0, 0x00, 0x20, 0x00, 2, 0, 0, 0]);
    // Server offers CRC, but the client did not: no check.
    reply(&mut c, ms(1), [0xC4, 0x00, 0x20, 0x00, 0, 0, 0, 0]);
    assert_eq!(one(&mut c), [0xA3, 0, 0, 0, 0, 0, 0, 0]);
    reply(&mut c, ms(2), [0x01, 1, 2, 3, 4, 5, 6, 7]);
    reply(&mut c, ms(3), [0x02, 8, 9, 10, 11, 12, 13, 14]);
    assert_eq!(one(&mut c), [0xA2, 2, 2, 0, 0, 0, 0, 0]);
    reply(&mut c, ms(4), [0x81, 15, 0, 0, 0, 0, 0, 0]);
    assert_eq!(one(&mut c), [0xA2, 1, 2, 0, 0, 0, 0, 0]);
    // n=6 unused bytes; a CRC that is not checked.
    reply(&mut c, ms(5), [0xD9, 0xDE, 0xAD, 0, 0, 0, 0, 0]);
    assert_eq!(one(&mut c), [0xA1, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(
        events(&mut c),
        vec![ClientEvent::Uploaded {
            index: 0x2000,
            sub: 0,
            data: (1..=15).collect(),
            padded: false
        }]
    );
}

#[test]
fn block_upload_crc_mismatch_aborts() {
    let mut c = client();
    c.upload_with(ms(0), 0x2000, 0, Method::Block).unwrap();
    sent(&mut c);
    reply(&mut c, ms(1), [0xC6, 0x00, 0x20, 0x00, 3, 0, 0, 0]);
    sent(&mut c);
    reply(&mut c, ms(2), [0x81, b'a', b'b', b'c', 0, 0, 0, 0]);
    assert_eq!(one(&mut c), [0xA2, 1, 127, 0, 0, 0, 0, 0]);
    let [lo, hi] = (crc16_xmodem(b"abc") ^ 1).to_le_bytes();
    reply(&mut c, ms(3), [0xD1, lo, hi, 0, 0, 0, 0, 0]);
    assert_eq!(
        one(&mut c),
        [0x80, 0x00, 0x20, 0x00, 0x04, 0x00, 0x04, 0x05]
    );
    assert_eq!(
        events(&mut c),
        failed(0x2000, 0, local(AbortCode::CrcError))
    );
}

#[test]
fn block_upload_rejects_sequence_numbers_beyond_the_block_size() {
    let mut c = SdoClient::new(ClientConfig {
        block_size: 4,
        ..config()
    });
    c.upload_with(ms(0), 0x2000, 0, Method::Block).unwrap();
    sent(&mut c);
    reply(&mut c, ms(1), [0xC4, 0x00, 0x20, 0x00, 0, 0, 0, 0]);
    sent(&mut c);
    reply(&mut c, ms(2), [0x05, 1, 2, 3, 4, 5, 6, 7]);
    assert_eq!(
        one(&mut c),
        [0x80, 0x00, 0x20, 0x00, 0x03, 0x00, 0x04, 0x05]
    );
    // An abort during a sub-block is a remote abort, not a segment.
    c.upload_with(ms(3), 0x2000, 0, Method::Block).unwrap();
    sent(&mut c);
    reply(&mut c, ms(4), [0xC4, 0x00, 0x20, 0x00, 0, 0, 0, 0]);
    sent(&mut c);
    events(&mut c);
    reply(
        &mut c,
        ms(5),
        [0x80, 0x00, 0x20, 0x00, 0x00, 0x00, 0x00, 0x08],
    );
    assert!(sent(&mut c).is_empty());
    assert_eq!(
        events(&mut c),
        failed(0x2000, 0, SdoError::RemoteAbort(AbortCode::GeneralError))
    );
}

#[test]
fn block_upload_without_size_stops_at_max_upload() {
    let mut c = SdoClient::new(ClientConfig {
        max_upload: 10,
        ..config()
    });
    c.upload_with(ms(0), 0x2000, 0, Method::Block).unwrap();
    sent(&mut c);
    reply(&mut c, ms(1), [0xC0, 0x00, 0x20, 0x00, 0, 0, 0, 0]);
    sent(&mut c);
    reply(&mut c, ms(2), [0x01, 1, 2, 3, 4, 5, 6, 7]);
    reply(&mut c, ms(3), [0x02, 8, 9, 10, 11, 12, 13, 14]);
    assert!(sent(&mut c).is_empty());
    reply(&mut c, ms(4), [0x03, 15, 16, 17, 18, 19, 20, 21]);
    assert_eq!(
        one(&mut c),
        [0x80, 0x00, 0x20, 0x00, 0x05, 0x00, 0x04, 0x05]
    );
    assert!(c.buf.capacity() <= 10);
}

#[test]
fn block_upload_follows_a_protocol_switch() {
    let mut c = SdoClient::new(ClientConfig {
        block_upload: true,
        ..config()
    });
    c.upload(ms(0), 0x1008, 0).unwrap();
    assert_eq!(one(&mut c), [0xA4, 0x08, 0x10, 0x00, 127, 0, 0, 0]);
    // Expedited answer: e=1, s=1, n=2.
    reply(&mut c, ms(1), [0x4B, 0x08, 0x10, 0x00, 0x34, 0x12, 0, 0]);
    assert_eq!(
        events(&mut c),
        vec![ClientEvent::Uploaded {
            index: 0x1008,
            sub: 0,
            data: vec![0x34, 0x12],
            padded: false
        }]
    );
    // Segmented answer: continue with upload segment requests.
    c.upload(ms(2), 0x1008, 0).unwrap();
    sent(&mut c);
    reply(&mut c, ms(3), [0x41, 0x08, 0x10, 0x00, 3, 0, 0, 0]);
    assert_eq!(one(&mut c), [0x60, 0, 0, 0, 0, 0, 0, 0]);
    reply(&mut c, ms(4), [0x09, b'a', b'b', b'c', 0, 0, 0, 0]);
    assert_eq!(
        events(&mut c),
        vec![ClientEvent::Uploaded {
            index: 0x1008,
            sub: 0,
            data: b"abc".to_vec(),
            padded: false
        }]
    );
}
