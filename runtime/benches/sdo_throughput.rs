//! SDO throughput on the virtual bus, on one core.
//!
//! 1. Frames per second of segmented and block transfers (upload and
//!    download): the runtime's SDO client and server, both in this thread,
//!    exchange frames through two ports of a `VirtualBus`. The frames of both
//!    directions are counted. "client" and "server" rows replay the recorded
//!    frames of the other side into one core alone, to show each one's cost.
//!    The goal is at least 1 000 000 frames/s, over 100 times what a 1 Mbit/s
//!    bus carries (at most about 9 000 frames/s).
//! 2. With the bit-time model at 1 Mbit/s: the payload throughput of block
//!    transfers as a share of the bus's theoretical maximum, taken as 8 data
//!    bytes per unstuffed 111-bit frame (SOF to intermission).
//!
//! Run: `cargo bench -p eds2rust-runtime --bench sdo_throughput`.

use std::hint::black_box;
use std::time::{Duration, Instant as StdInstant};

use eds2rust_runtime::od::{AccessRight, NodeId};
use eds2rust_runtime::sdo::Channel;
use eds2rust_runtime::sdo::client::{ClientConfig, ClientEvent, Method, SdoClient};
use eds2rust_runtime::sdo::server::{MemoryStore, SdoServer, ServerConfig};
use eds2rust_runtime::transport::virtual_bus::{VirtualBus, VirtualPort};
use eds2rust_runtime::{Frame, Instant, Service};

const VALUE_LEN: usize = 64 * 1024;
const OBJECT: (u16, u8) = (0x2000, 1);

struct Pair {
    client: SdoClient,
    server: SdoServer<MemoryStore>,
    client_port: VirtualPort,
    server_port: VirtualPort,
}

fn pair(bus: &VirtualBus) -> Pair {
    let channel = Channel::default_for(NodeId::new(5).unwrap());
    let mut store = MemoryStore::new();
    store.insert(OBJECT.0, OBJECT.1, AccessRight::Rw, &[0xA5; VALUE_LEN]);
    let mut sc = ServerConfig::new(channel);
    sc.max_download = VALUE_LEN;
    let mut cc = ClientConfig::new(channel);
    cc.max_upload = VALUE_LEN;
    Pair {
        client: SdoClient::new(cc),
        server: SdoServer::new(sc, store),
        client_port: bus.attach(),
        server_port: bus.attach(),
    }
}

/// Runs one transfer to its end; returns the frames it put on the bus, and
/// records them per direction when asked.
fn transfer(
    p: &mut Pair,
    upload: bool,
    method: Method,
    data: &[u8],
    record: Option<(&mut Vec<Frame>, &mut Vec<Frame>)>,
) -> u64 {
    let now = Instant::from_millis(1);
    if upload {
        p.client
            .upload_with(now, OBJECT.0, OBJECT.1, method)
            .unwrap();
    } else {
        p.client
            .download_with(now, OBJECT.0, OBJECT.1, data, method)
            .unwrap();
    }
    let (mut to_server, mut to_client) = match record {
        Some((a, b)) => (Some(a), Some(b)),
        None => (None, None),
    };
    let mut frames = 0u64;
    let mut finished = false;
    loop {
        while let Some(f) = p.client.poll_transmit() {
            p.client_port.transmit(&f);
            frames += 1;
        }
        while let Some(f) = p.server_port.try_recv() {
            if let Some(rec) = to_server.as_deref_mut() {
                rec.push(f);
            }
            p.server.handle_frame(now, &f);
            while let Some(f) = p.server.poll_transmit() {
                p.server_port.transmit(&f);
                frames += 1;
            }
        }
        while p.server.poll_event().is_some() {}
        while let Some(f) = p.client_port.try_recv() {
            if let Some(rec) = to_client.as_deref_mut() {
                rec.push(f);
            }
            p.client.handle_frame(now, &f);
        }
        if let Some(event) = p.client.poll_event() {
            match event {
                ClientEvent::Failed { error, .. } => panic!("transfer failed: {error}"),
                ClientEvent::Uploaded { data, .. } => assert_eq!(data.len(), VALUE_LEN),
                _ => {}
            }
            finished = true;
        }
        // The client's last frame (the end response of a block upload)
        // follows its event; the transfer is over when the server has it.
        if finished && p.server.is_idle() && p.server_port.pending() == 0 {
            return frames;
        }
    }
}

fn rate(frames: u64, elapsed: Duration) -> f64 {
    frames as f64 / elapsed.as_secs_f64()
}

/// Repeats `run` for at least `min` and returns (frames, elapsed).
fn timed(min: Duration, mut run: impl FnMut() -> u64) -> (u64, Duration) {
    let start = StdInstant::now();
    let mut frames = 0;
    while start.elapsed() < min {
        frames += run();
    }
    (frames, start.elapsed())
}

fn main() {
    let data = vec![0x5A; VALUE_LEN];
    let min = Duration::from_millis(if std::env::args().any(|a| a == "--quick") {
        100
    } else {
        1500
    });
    println!("SDO transfers of {VALUE_LEN} bytes on the virtual bus, one core");
    println!(
        "{:<26} {:>16} {:>16} {:>16}",
        "transfer", "both frames/s", "client frames/s", "server frames/s"
    );
    let mut worst = f64::INFINITY;
    for (name, upload, method) in [
        ("segmented upload", true, Method::Segmented),
        ("segmented download", false, Method::Segmented),
        ("block upload", true, Method::Block),
        ("block download", false, Method::Block),
    ] {
        let bus = VirtualBus::new();
        let mut p = pair(&bus);
        let (frames, elapsed) = timed(min, || transfer(&mut p, upload, method, &data, None));
        let both = rate(frames, elapsed);

        // Record one transfer's frames, then replay each side alone.
        let (mut to_server, mut to_client) = (Vec::new(), Vec::new());
        transfer(
            &mut p,
            upload,
            method,
            &data,
            Some((&mut to_server, &mut to_client)),
        );
        let (client_frames, client_elapsed) = timed(min, || {
            replay_client(&mut p.client, upload, method, &data, &to_client)
        });
        let (server_frames, server_elapsed) =
            timed(min, || replay_server(&mut p.server, &to_server));
        let client = rate(client_frames, client_elapsed);
        let server = rate(server_frames, server_elapsed);
        worst = worst.min(both);
        println!("{name:<26} {both:>16.0} {client:>16.0} {server:>16.0}");
    }
    println!(
        "slowest client+server loop: {worst:.0} frames/s ({}goal of 1 000 000 met)",
        if worst >= 1e6 { "" } else { "NOT " }
    );

    println!();
    println!("Bit-time model at 1 Mbit/s (block transfers of {VALUE_LEN} bytes)");
    let max_payload = 1e6 / 111.0 * 8.0;
    println!(
        "theoretical maximum: 8 bytes per 111-bit frame = {:.0} bytes/s",
        max_payload
    );
    for (name, upload) in [("block upload", true), ("block download", false)] {
        let bus = VirtualBus::with_bit_rate(1_000_000);
        let mut p = pair(&bus);
        let before = bus.stats();
        transfer(&mut p, upload, Method::Block, &data, None);
        let after = bus.stats();
        let busy = after.busy - before.busy;
        let frames = after.frames - before.frames;
        let throughput = VALUE_LEN as f64 / busy.as_secs_f64();
        println!(
            "{name:<16} {frames} frames, {} bits, {:.1} ms on the bus: {throughput:.0} payload bytes/s = {:.1} % of the maximum",
            after.bits - before.bits,
            busy.as_secs_f64() * 1e3,
            throughput / max_payload * 100.0
        );
    }
}

/// Feeds the client the server's recorded frames; counts frames handled and sent.
fn replay_client(
    client: &mut SdoClient,
    upload: bool,
    method: Method,
    data: &[u8],
    from_server: &[Frame],
) -> u64 {
    let now = Instant::from_millis(1);
    if upload {
        client.upload_with(now, OBJECT.0, OBJECT.1, method).unwrap();
    } else {
        client
            .download_with(now, OBJECT.0, OBJECT.1, data, method)
            .unwrap();
    }
    let mut frames = 0;
    while let Some(f) = client.poll_transmit() {
        black_box(f);
        frames += 1;
    }
    for f in from_server {
        client.handle_frame(now, f);
        frames += 1;
        while let Some(f) = client.poll_transmit() {
            black_box(f);
            frames += 1;
        }
    }
    match client.poll_event() {
        Some(ClientEvent::Failed { error, .. }) => panic!("replayed transfer failed: {error}"),
        Some(_) => {}
        None => panic!("replay did not finish the transfer"),
    }
    frames
}

/// Feeds the server the client's recorded frames; counts frames handled and sent.
fn replay_server(server: &mut SdoServer<MemoryStore>, from_client: &[Frame]) -> u64 {
    let now = Instant::from_millis(1);
    let mut frames = 0;
    for f in from_client {
        server.handle_frame(now, f);
        frames += 1;
        while let Some(f) = server.poll_transmit() {
            black_box(f);
            frames += 1;
        }
    }
    while server.poll_event().is_some() {}
    assert!(
        server.is_idle(),
        "replay did not finish the transfer: {} frames, first {:?}, last {:?}",
        from_client.len(),
        from_client.first(),
        from_client.last()
    );
    frames
}
