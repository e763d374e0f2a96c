//! [`SocketCanBus`] against the kernel's SocketCAN stack: classic frames
//! between two sockets, kernel filters, receive timeouts, and SDO transfers
//! (expedited, segmented, block) between the blocking client and a served
//! SDO server, also on an additional 29-bit SDO channel.
//!
//! These tests need a real CAN interface and are ignored by default:
//! `tests/vm/run.sh` runs them with `--ignored` inside a VM whose kernel has
//! vcan. Each test takes its own interface from `CAN_IFACES` (a
//! space-separated list, index per test); with only `CAN_IFACE` set they all
//! share that one, so run them with `--test-threads=1`.
#![cfg(all(target_os = "linux", feature = "socketcan"))]

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use eds2rust_runtime::blocking::{self, SdoClient};
use eds2rust_runtime::od::{AccessRight, NodeId};
use eds2rust_runtime::sdo::Channel;
use eds2rust_runtime::sdo::client::{ClientConfig, Method};
use eds2rust_runtime::sdo::server::{MemoryStore, SdoServer, ServerConfig};
use eds2rust_runtime::transport::socketcan::SocketCanBus;
use eds2rust_runtime::transport::{Bus, Clock};
use eds2rust_runtime::{CanId, Frame};

/// Interface indices in `CAN_IFACES`, one per test.
const FRAMES: usize = 0;
const FILTERS: usize = 1;
const TIMEOUTS: usize = 2;
const SDO: usize = 3;
#[cfg(feature = "tokio")]
const ASYNC: usize = 4;
const SDO_29_BIT: usize = 5;

/// Waits for frames that must arrive; generous for an emulated VM.
const ARRIVAL: Duration = Duration::from_secs(2);
/// Waits for frames that must not arrive.
const QUIET: Duration = Duration::from_millis(100);

/// The interface of test `index`: the `index`th entry of `CAN_IFACES`, or
/// else `CAN_IFACE`. Panics with what to set when neither is there.
fn iface(index: usize) -> String {
    if let Ok(list) = std::env::var("CAN_IFACES") {
        let names: Vec<&str> = list.split([' ', ',']).filter(|s| !s.is_empty()).collect();
        if let Some(name) = names.get(index) {
            return (*name).to_string();
        }
        panic!(
            "CAN_IFACES={list:?} names {} interfaces; this test uses entry {index}",
            names.len()
        );
    }
    match std::env::var("CAN_IFACE") {
        Ok(name) if !name.is_empty() => name,
        _ => panic!(
            "no CAN interface: set CAN_IFACE (one, with --test-threads=1) or CAN_IFACES \
             (one per test) to SocketCAN interfaces such as vcan0; tests/vm/run.sh does"
        ),
    }
}

fn open(name: &str) -> SocketCanBus {
    SocketCanBus::open(name).unwrap_or_else(|e| panic!("{e}"))
}

/// Reads and drops whatever a socket received before its filter was set.
fn drain(bus: &mut SocketCanBus) {
    while bus.recv(Duration::ZERO).unwrap().is_some() {}
}

/// Serves `server` on `bus` in a thread for at most a minute, until the
/// flag it returns is set; the thread gives the server's store back.
fn spawn_server(
    mut bus: SocketCanBus,
    mut server: SdoServer<MemoryStore>,
) -> (Arc<AtomicBool>, JoinHandle<std::io::Result<MemoryStore>>) {
    let stop = Arc::new(AtomicBool::new(false));
    let server_stop = Arc::clone(&stop);
    let thread = std::thread::spawn(move || {
        let deadline = Instant::now() + Duration::from_secs(60);
        blocking::serve(
            &mut bus,
            &Clock::new(),
            &mut server,
            &server_stop,
            Some(deadline),
            |_| {},
        )
        .map(|()| server.into_store())
    });
    (stop, thread)
}

fn std_frame(id: u16, data: &[u8]) -> Frame {
    Frame::new(CanId::Standard(id), data).unwrap()
}

#[test]
#[ignore = "needs a SocketCAN interface in CAN_IFACE: run by tests/vm/run.sh"]
fn classic_frames_pass_between_two_sockets() {
    let name = iface(FRAMES);
    let mut a = open(&name);
    let mut b = open(&name);
    assert_eq!(a.interface(), name);

    let payload = [0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88];
    let mut sent = Vec::new();
    for len in 0..=8 {
        sent.push(std_frame(0x123, &payload[..len]));
    }
    sent.push(std_frame(0x000, &[0xFF]));
    sent.push(std_frame(0x7FF, &[0x00, 0x01]));
    sent.push(Frame::new(CanId::Extended(0x1ABC_DEF0), &payload).unwrap());
    sent.push(Frame::new(CanId::Extended(0x0000_0123), &[]).unwrap());
    sent.push(Frame::new(CanId::Extended(0x1FFF_FFFF), &[0xA5; 3]).unwrap());
    sent.push(Frame::remote(CanId::Standard(0x701), 1).unwrap());
    sent.push(Frame::remote(CanId::Standard(0x123), 0).unwrap());
    sent.push(Frame::remote(CanId::Extended(0x18FF_0001), 8).unwrap());
    for frame in &sent {
        a.send(frame).unwrap();
    }
    for frame in &sent {
        let got = b.recv(ARRIVAL).unwrap();
        assert_eq!(got.as_ref(), Some(frame), "expected {frame}");
    }
    assert_eq!(b.recv(QUIET).unwrap(), None);
    // A raw socket does not receive its own frames (CAN_RAW_RECV_OWN_MSGS
    // is off by default).
    assert_eq!(a.recv(QUIET).unwrap(), None);

    // The other way, checked on the wire through the socketcan crate.
    use socketcan::{EmbeddedFrame, Frame as _, Id, Socket, StandardId};
    b.send(&std_frame(0x181, &[0x01, 0x02, 0x03])).unwrap();
    let raw = a.socket().read_frame_timeout(ARRIVAL).unwrap();
    assert_eq!(raw.id(), Id::Standard(StandardId::new(0x181).unwrap()));
    assert_eq!(raw.data(), [0x01, 0x02, 0x03]);
    assert!(!raw.is_remote_frame() && !raw.is_extended());
    b.send(&Frame::remote(CanId::Extended(0x0ABC_0001), 4).unwrap())
        .unwrap();
    let raw = a.socket().read_frame_timeout(ARRIVAL).unwrap();
    assert_eq!(raw.can_id().as_raw(), 0x0ABC_0001);
    assert!(raw.is_remote_frame() && raw.is_extended());
    assert_eq!(raw.dlc(), 4);
}

#[test]
#[ignore = "needs a SocketCAN interface in CAN_IFACE: run by tests/vm/run.sh"]
fn filters_admit_only_chosen_ids() {
    let name = iface(FILTERS);
    let mut tx = open(&name);
    // 0x581 exactly, and 0x180..=0x1FF (TPDO1 of every node).
    let mut rx = open(&name)
        .set_filters(&[(0x581, 0x7FF), (0x180, 0x780)])
        .unwrap();
    drain(&mut rx);
    let mut none = open(&name).set_filters(&[]).unwrap();
    drain(&mut none);

    let admitted = [
        std_frame(0x581, &[0x43, 0x00, 0x10, 0x00, 0x91, 0x01, 0x0F, 0x00]),
        std_frame(0x180, &[0x01]),
        std_frame(0x1FF, &[]),
        Frame::remote(CanId::Standard(0x181), 2).unwrap(),
    ];
    let refused = [
        std_frame(0x580, &[0x01]),
        std_frame(0x582, &[0x02]),
        std_frame(0x17F, &[0x03]),
        std_frame(0x200, &[0x04]),
        std_frame(0x601, &[0x05]),
        // Extended frames never pass, even with a matching low part.
        Frame::new(CanId::Extended(0x581), &[0x06]).unwrap(),
        Frame::new(CanId::Extended(0x1000_0181), &[0x07]).unwrap(),
    ];
    // Interleaved, so that order and selection are both checked.
    for (i, frame) in refused.iter().enumerate() {
        tx.send(frame).unwrap();
        if let Some(good) = admitted.get(i) {
            tx.send(good).unwrap();
        }
    }
    for frame in &admitted {
        assert_eq!(rx.recv(ARRIVAL).unwrap().as_ref(), Some(frame));
    }
    assert_eq!(rx.recv(QUIET).unwrap(), None);
    assert_eq!(none.recv(QUIET).unwrap(), None);
}

#[test]
#[ignore = "needs a SocketCAN interface in CAN_IFACE: run by tests/vm/run.sh"]
fn recv_times_out_with_none() {
    let name = iface(TIMEOUTS);
    let mut bus = open(&name).set_filters(&[(0x7E5, 0x7FF)]).unwrap();
    drain(&mut bus);
    for wait in [
        Duration::ZERO,
        Duration::from_millis(50),
        Duration::from_millis(300),
    ] {
        let start = Instant::now();
        assert_eq!(bus.recv(wait).unwrap(), None);
        let took = start.elapsed();
        assert!(took >= wait, "recv({wait:?}) returned after {took:?}");
        // Generous: the VM emulates its CPU.
        assert!(
            took < wait + Duration::from_millis(500),
            "recv({wait:?}) took {took:?}"
        );
    }
    // A frame that arrives while waiting ends the wait early.
    let mut tx = open(&name);
    let sender = std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(100));
        tx.send(&std_frame(0x7E5, &[0x04, 0x05])).unwrap();
    });
    let start = Instant::now();
    let got = bus.recv(Duration::from_secs(5)).unwrap();
    sender.join().unwrap();
    assert_eq!(got, Some(std_frame(0x7E5, &[0x04, 0x05])));
    assert!(start.elapsed() < Duration::from_secs(4));
}

#[test]
#[ignore = "needs a SocketCAN interface in CAN_IFACE: run by tests/vm/run.sh"]
fn sdo_transfers_between_client_and_served_server() {
    let name = iface(SDO);
    let node = NodeId::new(5).unwrap();
    let channel = Channel::default_for(node);
    assert_eq!(channel, Channel::standard(0x605, 0x585));

    let long: Vec<u8> = (0..1000u32).map(|i| (i * 7 + 3) as u8).collect();
    let text = b"eds2rust over vcan!".to_vec();
    let mut store = MemoryStore::new();
    store.insert(0x2000, 1, AccessRight::Rw, &[0x11, 0x22, 0x33, 0x44]);
    store.insert(0x2001, 0, AccessRight::Rw, &text);
    store.insert(0x2002, 0, AccessRight::Rw, &long);
    store.insert(0x2003, 0, AccessRight::Rw, &[0x00]);
    store.insert(0x2004, 0, AccessRight::Rw, &[0x00]);

    // Sees every frame of the transfers.
    let mut sniffer = open(&name);
    let server_bus = open(&name).set_id_filters(&[channel.request]).unwrap();
    let client_bus = open(&name).set_id_filters(&[channel.response]).unwrap();

    let server = SdoServer::new(ServerConfig::new(channel), store);
    let (stop, server) = spawn_server(server_bus, server);

    let mut client = SdoClient::new(client_bus, ClientConfig::new(channel));
    let results = (|| -> Result<(), blocking::Error> {
        // Expedited both ways.
        assert_eq!(client.upload(0x2000, 1)?, [0x11, 0x22, 0x33, 0x44]);
        client.download(0x2003, 0, &[0xA1, 0xB2])?;
        // Segmented both ways.
        assert_eq!(client.upload_with(0x2001, 0, Method::Standard)?, text);
        client.download_with(0x2004, 0, b"segmented!", Method::Segmented)?;
        // Block both ways.
        assert_eq!(client.upload_with(0x2002, 0, Method::Block)?, long);
        let back: Vec<u8> = long.iter().rev().copied().collect();
        client.download_with(0x2002, 0, &back, Method::Block)?;
        assert_eq!(client.upload_with(0x2002, 0, Method::Block)?, back);
        Ok(())
    })();
    stop.store(true, Ordering::Relaxed);
    let store = server.join().unwrap().unwrap();
    results.unwrap();
    assert_eq!(store.get(0x2003, 0), Some(&[0xA1, 0xB2][..]));
    assert_eq!(store.get(0x2004, 0), Some(&b"segmented!"[..]));

    // CiA 301 on the wire: the expedited upload is an initiate request
    // (ccs 2) and a response with e = 1, s = 1 and n = 0 (4 bytes).
    let request = sniffer.recv(ARRIVAL).unwrap();
    assert_eq!(
        request,
        Some(std_frame(0x605, &[0x40, 0x00, 0x20, 0x01, 0, 0, 0, 0]))
    );
    let response = sniffer.recv(ARRIVAL).unwrap();
    assert_eq!(
        response,
        Some(std_frame(
            0x585,
            &[0x43, 0x00, 0x20, 0x01, 0x11, 0x22, 0x33, 0x44]
        ))
    );
    // The expedited download: ccs 1, e = 1, s = 1, n = 2 (0x2B), answered
    // by scs 3 (0x60).
    assert_eq!(
        sniffer.recv(ARRIVAL).unwrap(),
        Some(std_frame(
            0x605,
            &[0x2B, 0x03, 0x20, 0x00, 0xA1, 0xB2, 0, 0]
        ))
    );
    assert_eq!(
        sniffer.recv(ARRIVAL).unwrap(),
        Some(std_frame(0x585, &[0x60, 0x03, 0x20, 0x00, 0, 0, 0, 0]))
    );
}

/// An SDO server with an additional 29-bit channel (what a device's 0x1201
/// with bit 29 in its COB-IDs configures) and a client on that channel:
/// the frames cross the kernel as extended frames, and the default 11-bit
/// channel still answers.
#[test]
#[ignore = "needs a SocketCAN interface in CAN_IFACE: run by tests/vm/run.sh"]
fn sdo_on_an_additional_29_bit_channel() {
    let name = iface(SDO_29_BIT);
    let node = NodeId::new(7).unwrap();
    let default = Channel::default_for(node);
    // COB-IDs as 0x1201 sub 1 and 2 hold them: bit 29 set, 29-bit ids.
    let extended = Channel::from_cob_ids(0x2000_0000 | 0x1ABC_0607, 0x2000_0000 | 0x1ABC_0587)
        .expect("valid 29-bit COB-IDs");
    assert_eq!(extended, Channel::extended(0x1ABC_0607, 0x1ABC_0587));
    assert_eq!(extended.cob_ids(), (0x3ABC_0607, 0x3ABC_0587));

    let long: Vec<u8> = (0..300u32).map(|i| (i * 11 + 5) as u8).collect();
    let mut store = MemoryStore::new();
    store.insert(0x2000, 0, AccessRight::Rw, &[0x01, 0x02, 0x03, 0x04]);
    store.insert(0x2001, 0, AccessRight::Rw, &long);

    let mut sniffer = open(&name);
    let server_bus = open(&name)
        .set_id_filters(&[default.request, extended.request])
        .unwrap();
    let client_bus = open(&name).set_id_filters(&[extended.response]).unwrap();
    let default_bus = open(&name).set_id_filters(&[default.response]).unwrap();

    let mut server = SdoServer::new(ServerConfig::new(default), store);
    server.set_extra_channels(vec![extended]);
    let (stop, server) = spawn_server(server_bus, server);

    let mut client = SdoClient::new(client_bus, ClientConfig::new(extended));
    let mut default_client = SdoClient::new(default_bus, ClientConfig::new(default));
    let results = (|| -> Result<(), blocking::Error> {
        assert_eq!(client.upload(0x2000, 0)?, [0x01, 0x02, 0x03, 0x04]);
        client.download_with(0x2001, 0, &long[..100], Method::Segmented)?;
        assert_eq!(client.upload_with(0x2001, 0, Method::Block)?, &long[..100]);
        // The default channel is served as well.
        assert_eq!(default_client.upload(0x2000, 0)?, [0x01, 0x02, 0x03, 0x04]);
        Ok(())
    })();
    stop.store(true, Ordering::Relaxed);
    let store = server.join().unwrap().unwrap();
    results.unwrap();
    assert_eq!(store.get(0x2001, 0), Some(&long[..100]));

    // On the wire: an extended-frame initiate request and its answer.
    assert_eq!(
        sniffer.recv(ARRIVAL).unwrap(),
        Some(
            Frame::new(
                CanId::Extended(0x1ABC_0607),
                &[0x40, 0x00, 0x20, 0x00, 0, 0, 0, 0]
            )
            .unwrap()
        )
    );
    assert_eq!(
        sniffer.recv(ARRIVAL).unwrap(),
        Some(
            Frame::new(
                CanId::Extended(0x1ABC_0587),
                &[0x43, 0x00, 0x20, 0x00, 1, 2, 3, 4]
            )
            .unwrap()
        )
    );
}

/// The tokio transport: frames both ways with a filter, then expedited,
/// segmented and block SDO transfers between the async client and an
/// async-served server, each on its own `AsyncSocketCanBus`.
#[cfg(feature = "tokio")]
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
#[ignore = "needs a SocketCAN interface in CAN_IFACE: run by tests/vm/run.sh"]
async fn tokio_transport_frames_filters_and_sdo() {
    use eds2rust_runtime::transport::AsyncBus;
    use eds2rust_runtime::transport::socketcan::AsyncSocketCanBus;

    let name = iface(ASYNC);
    let open_async = |name: &str| AsyncSocketCanBus::open(name).unwrap_or_else(|e| panic!("{e}"));
    let mut a = open_async(&name);
    let mut b = open_async(&name).set_filters(&[(0x181, 0x7FF)]).unwrap();
    // Drop what arrived before the filter was set.
    while let Ok(Ok(_)) = tokio::time::timeout(QUIET, b.recv()).await {}
    a.send(&std_frame(0x100, &[9])).await.unwrap();
    a.send(&std_frame(0x181, &[1, 2, 3])).await.unwrap();
    let got = tokio::time::timeout(ARRIVAL, b.recv())
        .await
        .expect("a frame in time");
    assert_eq!(got.unwrap(), std_frame(0x181, &[1, 2, 3]));
    assert!(
        tokio::time::timeout(QUIET, b.recv()).await.is_err(),
        "0x100 passed the filter"
    );

    let node = NodeId::new(6).unwrap();
    let channel = Channel::default_for(node);
    let long: Vec<u8> = (0..700u32).map(|i| (i * 13 + 1) as u8).collect();
    let mut store = MemoryStore::new();
    store.insert(0x2000, 0, AccessRight::Rw, &[0x78, 0x56, 0x34, 0x12]);
    store.insert(0x2001, 0, AccessRight::Rw, &long);
    let mut server_bus = open_async(&name)
        .set_id_filters(&[channel.request])
        .unwrap();
    let client_bus = open_async(&name)
        .set_id_filters(&[channel.response])
        .unwrap();
    let (stop_tx, stop_rx) = tokio::sync::oneshot::channel::<()>();
    let server = tokio::spawn(async move {
        let mut server = SdoServer::new(ServerConfig::new(channel), store);
        eds2rust_runtime::tokio::serve(
            &mut server_bus,
            &eds2rust_runtime::tokio::clock(),
            &mut server,
            async {
                let _ = stop_rx.await;
            },
            None,
            |_| {},
        )
        .await
        .map(|()| server.into_store())
    });
    let mut client =
        eds2rust_runtime::tokio::SdoClient::new(client_bus, ClientConfig::new(channel));
    assert_eq!(
        client.upload(0x2000, 0).await.unwrap(),
        [0x78, 0x56, 0x34, 0x12]
    );
    assert_eq!(
        client
            .upload_with(0x2001, 0, Method::Standard)
            .await
            .unwrap(),
        long
    );
    let back: Vec<u8> = long.iter().rev().copied().collect();
    client
        .download_with(0x2001, 0, &back, Method::Block)
        .await
        .unwrap();
    assert_eq!(
        client.upload_with(0x2001, 0, Method::Block).await.unwrap(),
        back
    );
    let _ = stop_tx.send(());
    let store = server.await.unwrap().unwrap();
    assert_eq!(store.get(0x2001, 0), Some(&back[..]));
}
