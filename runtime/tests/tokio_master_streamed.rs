//! Streamed SDO transfers of the tokio master under the paused clock:
//! a download read from a reader and an upload written to a writer, by
//! segments and by blocks, with progress; a failing source aborts with
//! 0x08000000; a dropped streamed upload aborts with 0x05040000 after
//! writing what came; the next transfer works after each.
#![cfg(feature = "tokio")]

#[macro_use]
mod support;

use support::tokio_rig::*;

use std::io::{self, Read};
use std::time::Duration;

use eds2rust_runtime::blocking::Error;
use eds2rust_runtime::sdo::Channel;
use eds2rust_runtime::sdo::client::{ClientConfig, Method, Progress};
use eds2rust_runtime::tokio::SdoClient;
use eds2rust_runtime::transport::AsyncBus;
use eds2rust_runtime::transport::virtual_bus::VirtualBus;
use eds2rust_runtime::{Frame, od};

/// 3000 bytes, none alike in a row.
fn data() -> Vec<u8> {
    (0..3000u32).map(|i| (i * 7 % 251) as u8).collect()
}

/// SDO requests to the device (0x600 + 0x20) the monitor saw.
fn requests(frames: &[Frame]) -> Vec<&Frame> {
    frames
        .iter()
        .filter(|f| f.standard_id() == Some(0x620))
        .collect()
}

#[tokio::test(start_paused = true)]
async fn a_reader_is_downloaded_and_a_writer_filled_by_segments_and_blocks() {
    let rig = Rig::new(|_| {}).await;
    let m = &rig.master;
    let dev = node(DEVICE);
    for method in [Method::Segmented, Method::Block] {
        let data = data();
        let mut steps: Vec<Progress> = Vec::new();
        m.download_from(
            dev,
            0x2100,
            0,
            &mut data.as_slice(),
            Some(3000),
            method,
            |p| steps.push(p),
        )
        .await
        .unwrap_or_else(|e| panic!("{method:?} download: {e}"));
        let last = steps.last().copied().expect("progress was reported");
        assert_eq!((last.done, last.total), (3000, Some(3000)), "{method:?}");
        assert!(steps.len() > 3, "{method:?}: {steps:?}");

        let mut back = Vec::new();
        let mut done = 0;
        let n = m
            .upload_into(dev, 0x2100, 0, &mut back, method, |p| done = p.done)
            .await
            .unwrap_or_else(|e| panic!("{method:?} upload: {e}"));
        assert_eq!((n, done), (3000, 3000), "{method:?}");
        assert_eq!(back, data, "{method:?}");
    }
    // Without a size (CiA 301: no size indicated), by segments.
    let data = data();
    m.write_from::<Blob, _, _>(dev, &mut &data[..10], None, Method::Segmented, |_| {})
        .await
        .unwrap();
    assert_eq!(m.read_bytes::<Blob>(dev).await.unwrap(), &data[..10]);
    let frames = rig.seen();
    // The download initiates of 0x2100:00: segmented with size (0x21), block
    // with size and CRC (0xC6), segmented without size (0x20).
    let initiates: Vec<u8> = requests(&frames)
        .iter()
        .map(|f| f.data())
        .filter(|d| d.get(1..4) == Some(&[0x00, 0x21, 0x00][..]))
        .filter_map(|d| d.first().copied())
        .filter(|c| matches!(c, 0x20 | 0x21 | 0xC6))
        .collect();
    assert_eq!(initiates, [0x21, 0xC6, 0x20]);
}

/// A reader that fails after `ok` bytes.
struct Failing {
    ok: usize,
}

impl Read for Failing {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if self.ok == 0 {
            return Err(io::Error::other("the disk went away"));
        }
        let n = buf.len().min(self.ok);
        buf[..n].fill(0x5A);
        self.ok -= n;
        Ok(n)
    }
}

#[tokio::test(start_paused = true)]
async fn a_failing_source_aborts_the_download_and_the_next_transfer_runs() {
    let rig = Rig::new(|_| {}).await;
    let m = &rig.master;
    let dev = node(DEVICE);
    rig.seen();
    let e = m
        .download_from(
            dev,
            0x2100,
            0,
            &mut Failing { ok: 2000 },
            Some(3000),
            Method::Segmented,
            |_| {},
        )
        .await
        .unwrap_err();
    assert!(
        matches!(&e, Error::Source(io) if io.to_string() == "the disk went away"),
        "{e:?}"
    );
    // The abort (0x80) for 0x2100:00 with 0x08000000 went out.
    tokio::time::sleep(Duration::from_millis(5)).await;
    let frames = rig.seen();
    let abort = requests(&frames)
        .into_iter()
        .find(|f| f.data().first() == Some(&0x80))
        .unwrap_or_else(|| panic!("no abort in {frames:?}"));
    assert_eq!(abort.to_string(), "620#8000210000000008");
    // The device still has its old value, and the next transfer runs.
    assert_eq!(m.read_bytes::<Blob>(dev).await.unwrap(), [0xA5; 100]);
    // A reader shorter than announced fails too.
    let e = m
        .download_from(
            dev,
            0x2100,
            0,
            &mut [1u8; 10].as_slice(),
            Some(20),
            Method::Segmented,
            |_| {},
        )
        .await
        .unwrap_err();
    assert!(
        e.to_string()
            .contains("the data ended after 10 of the 20 bytes announced"),
        "{e}"
    );
}

#[tokio::test(start_paused = true)]
async fn a_dropped_streamed_upload_is_aborted_and_the_next_succeeds() {
    let rig = Rig::new(|_| {}).await;
    // Node 0x31 is a scripted peer: a segmented upload of 20 bytes whose
    // first segment comes, then nothing.
    let mut peer = rig.bus.attach();
    let script = tokio::spawn(async move {
        start_segmented_upload(&mut peer).await;
        let data = frame(0x5B1, &[0x00, b'e', b'd', b's', b'2', b'r', b'u', b's']);
        AsyncBus::send(&mut peer, &data).await.unwrap();
        let next = recv_from(&mut peer, 0x631).await.unwrap();
        assert_eq!(next.to_string(), "631#7000000000000000");
        // The abort of the dropped call.
        recv_from(&mut peer, 0x631).await.unwrap()
    });
    let mut sink = Vec::new();
    let upload =
        rig.master
            .upload_into(node(0x31), 0x1008, 0, &mut sink, Method::Segmented, |_| {});
    let cut = tokio::time::timeout(Duration::from_millis(100), upload).await;
    assert!(cut.is_err(), "the upload ended: {cut:?}");
    // The first segment was written as it came: streamed, not held.
    assert_eq!(sink, b"eds2rus");
    let abort = tokio::time::timeout(Duration::from_millis(10), script)
        .await
        .expect("no abort frame")
        .unwrap();
    // Abort 0x05040000 for (0x1008, 0).
    assert_eq!(abort.to_string(), "631#8008100000000405");
    // The next transfer with the device runs.
    let mut back = Vec::new();
    rig.master
        .upload_into(node(DEVICE), 0x1008, 0, &mut back, Method::Block, |_| {})
        .await
        .unwrap();
    assert_eq!(back, b"eds2rust test device");
}

#[test]
fn streamed_futures_are_send() {
    fn assert_send<T: Send>(_: &T) {}
    let bus = eds2rust_runtime::transport::virtual_bus::VirtualBus::new();
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_time()
        .build()
        .unwrap();
    let _entered = runtime.enter();
    let core = eds2rust_runtime::master::Master::new(node(1), None);
    let (m, _driver) = eds2rust_runtime::tokio::Master::new(bus.attach(), core);
    let mut reader: &[u8] = &[1, 2, 3];
    let download = m.download_from(node(2), 0x2100, 0, &mut reader, None, Method::Auto, |_| {});
    assert_send(&download);
    let mut writer = Vec::new();
    let upload = m.upload_into(node(2), 0x2100, 0, &mut writer, Method::Auto, |_| {});
    assert_send(&upload);
}

// The COB-ID entry of TPDO1 (0x1800:01) as a one-element ARRAY, for the
// run-time element calls.
entry!(Tpdo1CobId, 0x1800, 1, Unsigned32, Rw, u32);

impl od::Array for Tpdo1CobId {
    const FIRST: u8 = 1;
    const LAST: u8 = 1;
}

// The DOMAIN 0x2100:00 as a one-element ARRAY of bytes.
entry!(Blobs, 0x2100, 0, Domain, Rw, od::bytes::Domain);

impl od::Array for Blobs {
    const FIRST: u8 = 0;
    const LAST: u8 = 0;
}

#[tokio::test(start_paused = true)]
async fn the_tokio_sdo_client_streams_and_takes_array_elements_as_the_master_does() {
    let bus = VirtualBus::new();
    let _device = spawn_device(bus.attach());
    let config = ClientConfig::new(Channel::default_for(node(DEVICE)));
    let mut client = SdoClient::new(bus.attach(), config);
    for method in [Method::Segmented, Method::Block] {
        let data = data();
        let mut last = None;
        client
            .download_from(0x2100, 0, &mut data.as_slice(), Some(3000), method, |p| {
                last = Some(p.done)
            })
            .await
            .unwrap_or_else(|e| panic!("{method:?} download: {e}"));
        assert_eq!(last, Some(3000), "{method:?}");
        let mut back = Vec::new();
        let n = client
            .read_into::<Blob, _, _>(&mut back, method, |_| {})
            .await
            .unwrap_or_else(|e| panic!("{method:?} upload: {e}"));
        assert_eq!((n, back), (3000, data), "{method:?}");
    }
    client
        .write_from::<Blob, _, _>(&mut &b"abc"[..], None, Method::Segmented, |_| {})
        .await
        .unwrap();
    let mut back = Vec::new();
    client
        .upload_into(0x2100, 0, &mut back, Method::Segmented, |_| {})
        .await
        .unwrap();
    assert_eq!(back, b"abc");

    let first = od::Element::<Tpdo1CobId>::new(1).unwrap();
    assert_eq!(client.read_at(first).await.unwrap(), 0x1A0);
    client.write_at(first, 0x1A1).await.unwrap();
    assert_eq!(client.read_at(first).await.unwrap(), 0x1A1);
    client.write_at(first, 0x1A0).await.unwrap();
    let blob = od::Element::<Blobs>::new(0).unwrap();
    client.write_bytes_at(blob, b"element").await.unwrap();
    assert_eq!(client.read_bytes_at(blob).await.unwrap(), b"element");

    // A failure names the node (the channel's), the object and the abort.
    let e = client.upload(0x2001, 0).await.unwrap_err();
    assert!(
        matches!(
            e,
            Error::Sdo { node: Some(n), index: 0x2001, sub: 0, .. } if n == node(DEVICE)
        ),
        "{e:?}"
    );
    assert!(
        e.to_string()
            .starts_with("SDO transfer of 0x2001:0 with node 32: "),
        "{e}"
    );
}
