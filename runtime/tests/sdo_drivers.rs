//! The blocking and tokio SDO drivers over the virtual bus, against a fake
//! node that answers with hand-written CiA 301 frames (no SDO server core).

#[macro_use]
mod support;

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use eds2rust_runtime::blocking::{self, Error};
use eds2rust_runtime::od::{DataType, ValueError, bytes};
use eds2rust_runtime::sdo::client::ClientConfig;
use eds2rust_runtime::sdo::typed::LengthNote;
use eds2rust_runtime::sdo::{AbortCode, Channel, SdoError};
use eds2rust_runtime::transport::virtual_bus::{VirtualBus, VirtualPort};
use eds2rust_runtime::{CanId, Frame};
use support::assert_sdo_timeout;

entry!(ProducerHeartbeatTime, 0x1017, 0, Unsigned16, Rw, u16);
entry!(
    DeviceName,
    0x1008,
    0,
    VisibleString,
    Const,
    bytes::VisibleString
);
entry!(Temperature, 0x2000, 1, Integer16, Ro, i16);
entry!(Counter, 0x2001, 0, Unsigned16, Ro, u16);
entry!(BadName, 0x2002, 0, VisibleString, Ro, bytes::VisibleString);
entry!(Label, 0x2004, 0, VisibleString, Rw, bytes::VisibleString);
entry!(Silent, 0x2FFF, 0, Unsigned32, Rw, u32);
entry!(Mode, 0x2003, 0, Integer8, Ro, i8);
entry!(Level, 0x2005, 0, Unsigned8, Ro, u8);
entry!(Wide, 0x2006, 0, Unsigned24, Ro, u32);

/// Node 5: requests on 0x605, answers on 0x585.
const REQUEST: u16 = 0x605;
const RESPONSE: u16 = 0x585;

fn config(timeout: Duration) -> ClientConfig {
    let mut config = ClientConfig::new(Channel::standard(REQUEST, RESPONSE));
    config.timeout = timeout;
    config
}

/// The fake node's object values and the requests it saw.
#[derive(Default)]
struct FakeNode {
    heartbeat: [u8; 2],
    requests: Vec<[u8; 8]>,
}

impl FakeNode {
    /// The answer to one request, written out by hand from CiA 301.
    fn answer(&mut self, request: &Frame) -> Option<Frame> {
        if request.standard_id() != Some(REQUEST) {
            return None;
        }
        let req = *request.data_padded();
        self.requests.push(req);
        let [hb_lo, hb_hi] = self.heartbeat;
        let response: [u8; 8] = match req {
            // Upload 0x1017:00: expedited, size indicated, 2 bytes (0x4B).
            [0x40, 0x17, 0x10, 0x00, ..] => [0x4B, 0x17, 0x10, 0x00, hb_lo, hb_hi, 0, 0],
            // Download 0x1017:00, expedited, 2 bytes (0x2B): confirm (0x60).
            [0x2B, 0x17, 0x10, 0x00, lo, hi, ..] => {
                self.heartbeat = [lo, hi];
                [0x60, 0x17, 0x10, 0x00, 0, 0, 0, 0]
            }
            // Upload 0x1008:00: "Fan", 3 bytes (0x47).
            [0x40, 0x08, 0x10, 0x00, ..] => [0x47, 0x08, 0x10, 0x00, b'F', b'a', b'n', 0],
            // Upload 0x2000:01: -200 = 0xFF38 (0x4B).
            [0x40, 0x00, 0x20, 0x01, ..] => [0x4B, 0x00, 0x20, 0x01, 0x38, 0xFF, 0, 0],
            // Upload 0x2001:00: 4 bytes (0x43) for a 2-byte entry.
            [0x40, 0x01, 0x20, 0x00, ..] => [0x43, 0x01, 0x20, 0x00, 1, 2, 3, 4],
            // Upload 0x2003:00: expedited without size (0x42), 4 bytes of
            // which an INTEGER8 is the first.
            [0x40, 0x03, 0x20, 0x00, ..] => [0x42, 0x03, 0x20, 0x00, 0xFD, 0xAA, 0xBB, 0xCC],
            // Upload 0x2005:00: one data byte (0x4F) in a 5-byte frame.
            [0x40, 0x05, 0x20, 0x00, ..] => {
                let frame = [0x4F, 0x05, 0x20, 0x00, 0x07];
                return Some(Frame::new(CanId::Standard(RESPONSE), &frame).unwrap());
            }
            // Upload 0x2006:00: UNSIGNED24 without size (0x42).
            [0x40, 0x06, 0x20, 0x00, ..] => [0x42, 0x06, 0x20, 0x00, 0x01, 0x02, 0x03, 0x99],
            // Upload 0x2002:00: "ca" then 0xE9 (0x47).
            [0x40, 0x02, 0x20, 0x00, ..] => [0x47, 0x02, 0x20, 0x00, b'c', b'a', 0xE9, 0],
            // Download 0x2004:00, 3 bytes (0x27): confirm.
            [0x27, 0x04, 0x20, 0x00, ..] => [0x60, 0x04, 0x20, 0x00, 0, 0, 0, 0],
            // 0x2FFF never answers.
            [_, 0xFF, 0x2F, ..] => return None,
            // Aborts from the client need no answer.
            [0x80, ..] => return None,
            // Anything else: abort 0x06020000 (object does not exist).
            [_, idx_lo, idx_hi, sub, ..] => [0x80, idx_lo, idx_hi, sub, 0x00, 0x00, 0x02, 0x06],
        };
        Some(Frame::new(CanId::Standard(RESPONSE), &response).unwrap())
    }
}

/// Runs the fake node on its own thread until the returned flag is set.
fn spawn_node(
    mut port: VirtualPort,
    heartbeat: u16,
) -> (Arc<AtomicBool>, std::thread::JoinHandle<FakeNode>) {
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    let handle = std::thread::spawn(move || {
        let mut node = FakeNode {
            heartbeat: heartbeat.to_le_bytes(),
            ..FakeNode::default()
        };
        while !flag.load(Ordering::Relaxed) {
            if let Some(request) = port.recv_timeout(Duration::from_millis(5))
                && let Some(response) = node.answer(&request)
            {
                port.transmit(&response);
            }
        }
        let _ = &mut port;
        node
    });
    (stop, handle)
}

#[test]
fn blocking_typed_access() {
    let bus = VirtualBus::new();
    let (stop, node) = spawn_node(bus.attach(), 1000);
    let mut client = blocking::SdoClient::new(bus.attach(), config(Duration::from_millis(200)));

    assert_eq!(client.read::<ProducerHeartbeatTime>().unwrap(), 1000);
    client.write::<ProducerHeartbeatTime>(250).unwrap();
    assert_eq!(client.read::<ProducerHeartbeatTime>().unwrap(), 250);
    assert_eq!(client.read::<Temperature>().unwrap(), -200);
    assert_eq!(client.read_string::<DeviceName>().unwrap(), "Fan");
    assert_eq!(client.read_bytes::<DeviceName>().unwrap(), b"Fan");
    client.write_bytes::<Label>(b"abc").unwrap();
    assert_eq!(client.upload(0x1017, 0).unwrap(), [0xFA, 0x00]);

    // 4 bytes announced for a 2-byte entry: the leading two, and a note.
    assert_eq!(client.read::<Counter>().unwrap(), 0x0201);
    let note = LengthNote {
        index: 0x2001,
        sub: 0,
        data_type: DataType::Unsigned16,
        received: 4,
    };
    assert_eq!(client.take_length_notes(), [note]);
    // No size indicated: the leading bytes, nothing to note.
    assert_eq!(client.read::<Mode>().unwrap(), -3);
    assert_eq!(client.read::<Wide>().unwrap(), 0x03_0201);
    // A 5-byte response.
    assert_eq!(client.read::<Level>().unwrap(), 7);
    assert!(client.take_length_notes().is_empty());
    assert!(matches!(
        client.read_string::<BadName>(),
        Err(Error::NotVisible {
            offset: 2,
            byte: 0xE9,
            ..
        })
    ));
    assert!(matches!(
        client.download(0x3000, 2, &[1]),
        Err(Error::Sdo {
            error: SdoError::RemoteAbort(AbortCode::ObjectDoesNotExist),
            ..
        })
    ));

    stop.store(true, Ordering::Relaxed);
    let node = node.join().unwrap();
    // The requests, byte for byte (CiA 301 expedited layouts).
    assert_eq!(node.requests[0], [0x40, 0x17, 0x10, 0x00, 0, 0, 0, 0]);
    assert_eq!(node.requests[1], [0x2B, 0x17, 0x10, 0x00, 0xFA, 0x00, 0, 0]);
    assert_eq!(
        node.requests[6],
        [0x27, 0x04, 0x20, 0x00, b'a', b'b', b'c', 0]
    );
}

#[test]
fn blocking_strict_lengths_refuse_a_longer_value() {
    let bus = VirtualBus::new();
    let (stop, node) = spawn_node(bus.attach(), 1000);
    let mut strict = config(Duration::from_millis(200));
    strict.strict_lengths = true;
    let mut client = blocking::SdoClient::new(bus.attach(), strict);
    assert!(matches!(
        client.read::<Counter>(),
        Err(Error::Value {
            error: ValueError::Length {
                expected: 2,
                actual: 4
            },
            ..
        })
    ));
    // Padding of a response without size is no excess.
    assert_eq!(client.read::<Mode>().unwrap(), -3);
    assert!(client.take_length_notes().is_empty());
    stop.store(true, Ordering::Relaxed);
    node.join().unwrap();
}

#[test]
fn blocking_silent_node_times_out_with_an_abort() {
    let bus = VirtualBus::new();
    let (stop, node) = spawn_node(bus.attach(), 0);
    let mut client = blocking::SdoClient::new(bus.attach(), config(Duration::from_millis(50)));
    let start = std::time::Instant::now();
    assert_sdo_timeout(&client.read::<Silent>().unwrap_err());
    let took = start.elapsed();
    assert!(
        took >= Duration::from_millis(50) && took < Duration::from_secs(2),
        "{took:?}"
    );
    // The client is usable again.
    assert_eq!(client.read::<ProducerHeartbeatTime>().unwrap(), 0);
    stop.store(true, Ordering::Relaxed);
    let node = node.join().unwrap();
    assert_eq!(node.requests[0], [0x40, 0xFF, 0x2F, 0x00, 0, 0, 0, 0]);
    // Abort 0x05040000 (SDO protocol timed out).
    assert_eq!(
        node.requests[1],
        [0x80, 0xFF, 0x2F, 0x00, 0x00, 0x00, 0x04, 0x05]
    );
}

#[cfg(feature = "tokio")]
mod tokio_drivers {
    use super::*;
    use eds2rust_runtime::tokio::SdoClient;
    use eds2rust_runtime::transport::AsyncBus;

    /// Runs the fake node as a task until the client's side is done.
    fn spawn_node(mut port: VirtualPort, heartbeat: u16) -> ::tokio::task::JoinHandle<FakeNode> {
        ::tokio::spawn(async move {
            let mut node = FakeNode {
                heartbeat: heartbeat.to_le_bytes(),
                ..FakeNode::default()
            };
            loop {
                let request = port.recv().await.unwrap();
                if request.standard_id() == Some(0x000) {
                    // The test's "stop" frame.
                    return node;
                }
                if let Some(response) = node.answer(&request) {
                    AsyncBus::send(&mut port, &response).await.unwrap();
                }
            }
        })
    }

    fn stop_frame() -> Frame {
        Frame::new(CanId::Standard(0), &[]).unwrap()
    }

    #[::tokio::test]
    async fn async_typed_access() {
        let bus = VirtualBus::new();
        let node = spawn_node(bus.attach(), 1000);
        let mut client = SdoClient::new(bus.attach(), config(Duration::from_millis(200)));
        assert_eq!(client.read::<ProducerHeartbeatTime>().await.unwrap(), 1000);
        client.write::<ProducerHeartbeatTime>(250).await.unwrap();
        assert_eq!(client.read::<ProducerHeartbeatTime>().await.unwrap(), 250);
        assert_eq!(client.read::<Temperature>().await.unwrap(), -200);
        assert_eq!(client.read_string::<DeviceName>().await.unwrap(), "Fan");
        assert_eq!(client.read_bytes::<DeviceName>().await.unwrap(), b"Fan");
        client.write_bytes::<Label>(b"abc").await.unwrap();
        assert_eq!(client.read::<Counter>().await.unwrap(), 0x0201);
        assert_eq!(client.take_length_notes().len(), 1);
        assert_eq!(client.read::<Mode>().await.unwrap(), -3);
        assert!(client.take_length_notes().is_empty());
        assert!(matches!(
            client.upload(0x3000, 1).await,
            Err(Error::Sdo {
                error: SdoError::RemoteAbort(AbortCode::ObjectDoesNotExist),
                ..
            })
        ));
        AsyncBus::send(client.bus_mut(), &stop_frame())
            .await
            .unwrap();
        let node = node.await.unwrap();
        assert_eq!(node.requests[1], [0x2B, 0x17, 0x10, 0x00, 0xFA, 0x00, 0, 0]);
    }

    #[::tokio::test(start_paused = true)]
    async fn async_silent_node_times_out_in_virtual_time() {
        let bus = VirtualBus::new();
        let node = spawn_node(bus.attach(), 7);
        let mut client = SdoClient::new(bus.attach(), config(Duration::from_millis(500)));
        let start = ::tokio::time::Instant::now();
        assert_sdo_timeout(&client.read::<Silent>().await.unwrap_err());
        let took = start.elapsed();
        assert!(
            took >= Duration::from_millis(500) && took < Duration::from_millis(600),
            "{took:?}"
        );
        assert_eq!(client.read::<ProducerHeartbeatTime>().await.unwrap(), 7);
        AsyncBus::send(client.bus_mut(), &stop_frame())
            .await
            .unwrap();
        let node = node.await.unwrap();
        assert_eq!(
            node.requests[1],
            [0x80, 0xFF, 0x2F, 0x00, 0x00, 0x00, 0x04, 0x05]
        );
    }

    #[test]
    fn futures_are_send() {
        fn assert_send<T: Send>(_: T) {}
        let bus = VirtualBus::new();
        let mut client = SdoClient::with_clock(
            bus.attach(),
            config(Duration::from_millis(10)),
            eds2rust_runtime::transport::Clock::new(),
        );
        assert_send(client.read::<ProducerHeartbeatTime>());
        assert_send(client.upload(0x1000, 0));
    }
}
