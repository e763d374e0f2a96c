//! Streamed downloads and uploads: frames written from the CiA 301 layouts
//! for a download without size indication, and whole transfers against the
//! runtime's SDO server core for every size, chunking and protocol, with the
//! client's memory bounded by its window.

use super::*;
use crate::od::AccessRight;
use crate::sdo::server::{MemoryStore, SdoServer, ServerConfig};

#[test]
fn a_segmented_download_without_size_indication() {
    let mut c = client();
    c.download_stream(ms(0), 0x1F50, 1, None, Method::Segmented)
        .unwrap();
    // ccs=1, e=0, s=0: no size.
    assert_eq!(one(&mut c), [0x20, 0x50, 0x1F, 0x01, 0, 0, 0, 0]);
    assert_eq!(c.wants_data(), WINDOW);
    assert_eq!(c.feed(ms(0), &[1, 2, 3, 4, 5, 6, 7, 8, 9, 10]), 10);
    assert!(
        sent(&mut c).is_empty(),
        "nothing before the initiate response"
    );
    reply(&mut c, ms(1), [0x60, 0x50, 0x1F, 0x01, 0, 0, 0, 0]);
    // Toggle 0, 7 bytes (n=0), not last: more data follows it.
    assert_eq!(one(&mut c), [0x00, 1, 2, 3, 4, 5, 6, 7]);
    reply(&mut c, ms(2), [0x20, 0, 0, 0, 0, 0, 0, 0]);
    // Three bytes left: whether they end the value is not known yet.
    assert!(sent(&mut c).is_empty());
    assert_eq!(
        c.poll_timeout(),
        None,
        "waiting for the caller, not the server"
    );
    assert_eq!(
        c.progress(),
        Some(Progress {
            done: 7,
            total: None
        })
    );
    c.end_of_data(ms(3));
    // Toggle 1, n=4 (3 bytes), last: 0x10 | 4 << 1 | 1.
    assert_eq!(one(&mut c), [0x19, 8, 9, 10, 0, 0, 0, 0]);
    reply(&mut c, ms(4), [0x30, 0, 0, 0, 0, 0, 0, 0]);
    assert_eq!(
        events(&mut c),
        vec![ClientEvent::Downloaded {
            index: 0x1F50,
            sub: 1
        }]
    );
}

#[test]
fn a_sized_stream_that_ends_early_is_aborted() {
    let mut c = client();
    c.download_stream(ms(0), 0x1F50, 1, Some(20), Method::Segmented)
        .unwrap();
    // ccs=1, s=1: size 20.
    assert_eq!(one(&mut c), [0x21, 0x50, 0x1F, 0x01, 20, 0, 0, 0]);
    assert_eq!(c.wants_data(), 20);
    c.feed(ms(0), &[0; 5]);
    assert_eq!(c.wants_data(), 15);
    c.end_of_data(ms(1));
    assert_eq!(
        one(&mut c),
        [0x80, 0x50, 0x1F, 0x01, 0x00, 0x00, 0x00, 0x08]
    );
    assert_eq!(
        events(&mut c),
        failed(0x1F50, 1, local(AbortCode::GeneralError))
    );
}

/// Runs one transfer between `client` and `server` in-process, feeding a
/// streamed download from `data` in chunks of `chunk` bytes and taking a
/// streamed upload as it arrives; returns the client's event, the upload
/// data taken and the most memory the client held.
fn exchange(
    client: &mut SdoClient,
    server: &mut SdoServer<MemoryStore>,
    data: &[u8],
    chunk: usize,
) -> (ClientEvent, Vec<u8>, usize) {
    let mut fed = 0;
    let mut taken = Vec::new();
    let mut most = 0;
    let mut now = ms(0);
    for _ in 0..100_000 {
        while client.wants_data() > 0 && fed < data.len() {
            let end = (fed + chunk).min(data.len());
            fed += client.feed(now, &data[fed..end]);
        }
        if fed == data.len() {
            client.end_of_data(now);
        }
        while let Some(frame) = client.poll_transmit() {
            server.handle_frame(now, &frame);
        }
        while let Some(frame) = server.poll_transmit() {
            client.handle_frame(now, &frame);
        }
        let ready = client.received().to_vec();
        client.consume(ready.len());
        taken.extend(ready);
        most = most.max(client.buffer_capacity());
        while server.poll_event().is_some() {}
        if let Some(event) = client.poll_event() {
            return (event, taken, most);
        }
        now += Duration::from_millis(1);
    }
    panic!("the transfer did not end");
}

fn channel() -> Channel {
    Channel::standard(REQUEST, RESPONSE)
}

fn server(value: &[u8]) -> SdoServer<MemoryStore> {
    let mut store = MemoryStore::new();
    store.insert(0x1F50, 1, AccessRight::Rw, value);
    let mut config = ServerConfig::new(channel());
    config.max_download = 1 << 21;
    SdoServer::new(config, store)
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(48))]

    #[test]
    fn streamed_downloads_arrive_whole_with_a_bounded_window(
        len in 0usize..4000,
        chunk in 1usize..1200,
        sized: bool,
        block: bool,
        seed: u8,
    ) {
        let data: Vec<u8> = (0..len).map(|i| (i as u8).wrapping_mul(31) ^ seed).collect();
        let mut s = server(&[]);
        let mut c = client();
        let method = if block { Method::Block } else { Method::Segmented };
        let size = sized.then_some(len as u32);
        c.download_stream(ms(0), 0x1F50, 1, size, method).unwrap();
        let (event, _, most) = exchange(&mut c, &mut s, &data, chunk);
        proptest::prop_assert_eq!(event, ClientEvent::Downloaded { index: 0x1F50, sub: 1 });
        proptest::prop_assert_eq!(s.store().get(0x1F50, 1), Some(&data[..]));
        // The window, never the value (VecDeque rounds capacities up).
        proptest::prop_assert!(most <= 2 * WINDOW, "held {} bytes", most);
    }

    #[test]
    fn streamed_uploads_hand_over_every_byte_as_it_arrives(
        len in 0usize..4000,
        block: bool,
        seed: u8,
    ) {
        let data: Vec<u8> = (0..len).map(|i| (i as u8).wrapping_mul(7) ^ seed).collect();
        let mut s = server(&data);
        let mut c = client();
        let method = if block { Method::Block } else { Method::Standard };
        c.upload_stream(ms(0), 0x1F50, 1, method).unwrap();
        let (event, mut taken, most) = exchange(&mut c, &mut s, &[], 1);
        let ClientEvent::Uploaded { data: rest, .. } = event else {
            return Err(proptest::test_runner::TestCaseError::fail(format!("{event:?}")));
        };
        taken.extend(rest);
        proptest::prop_assert_eq!(taken, data);
        proptest::prop_assert!(most <= 1024, "held {} bytes", most);
    }
}

#[test]
fn empty_streams_end_at_once_sized_or_not() {
    for (size, block) in [
        (Some(0), false),
        (Some(0), true),
        (None, false),
        (None, true),
    ] {
        let mut s = server(&[1, 2, 3]);
        let mut c = client();
        let method = if block {
            Method::Block
        } else {
            Method::Segmented
        };
        c.download_stream(ms(0), 0x1F50, 1, size, method).unwrap();
        let (event, _, _) = exchange(&mut c, &mut s, &[], 1);
        assert_eq!(
            event,
            ClientEvent::Downloaded {
                index: 0x1F50,
                sub: 1
            },
            "{size:?} {method:?}"
        );
        assert_eq!(s.store().get(0x1F50, 1), Some(&[][..]));
    }
}

#[test]
fn a_streamed_block_upload_checks_the_crc_over_all_it_handed_over() {
    let data: Vec<u8> = (0..2000u32).map(|i| (i * 3) as u8).collect();
    let mut s = server(&data);
    let mut c = client();
    c.upload_stream(ms(0), 0x1F50, 1, Method::Block).unwrap();
    let (event, taken, _) = exchange(&mut c, &mut s, &[], 1);
    assert!(taken.len() >= 2000 - 7, "handed over while running");
    assert!(matches!(event, ClientEvent::Uploaded { .. }));
}
