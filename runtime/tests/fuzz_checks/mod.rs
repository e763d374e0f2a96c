//! The bodies of the fuzz targets: each takes arbitrary bytes, feeds them to
//! a frame decoder or a protocol core, and panics only when a property is
//! broken. The cargo-fuzz targets in runtime/fuzz run them coverage-guided;
//! tests/decoders.rs runs them with proptest in CI.
#![allow(dead_code)]

use std::time::Duration;

use eds2rust_runtime::emcy::{Emcy, EmcyConsumer};
use eds2rust_runtime::guarding::{GuardResponder, NodeGuard};
use eds2rust_runtime::heartbeat::{HeartbeatConsumer, parse_heartbeat};
use eds2rust_runtime::nmt::{NmtMaster, NmtSlave, parse_command};
use eds2rust_runtime::od::{AccessRight, NodeId};
use eds2rust_runtime::sdo::Channel;
use eds2rust_runtime::sdo::client::{ClientConfig, Method, SdoClient};
use eds2rust_runtime::sdo::proto::{BlockSegment, Request, Response};
use eds2rust_runtime::sdo::server::{MemoryStore, SdoServer, ServerConfig};
use eds2rust_runtime::sync::{SyncConsumer, parse_sync};
use eds2rust_runtime::trace::candump::{self, Format};
use eds2rust_runtime::{CanId, Frame, Instant, Service};

/// Most frames a core may want to send in answer to one input: a whole
/// sub-block of 127 segments plus a little.
const MAX_FRAMES_PER_INPUT: usize = 130;
/// Most events per input.
const MAX_EVENTS_PER_INPUT: usize = 256;

/// Splits fuzz input into (time step, frame) pairs: 2 bytes of id and flags,
/// 1 byte of length and time step, then up to 8 data bytes.
pub fn frames(data: &[u8]) -> Vec<(Duration, Frame)> {
    let mut out = Vec::new();
    let mut rest = data;
    while rest.len() >= 3 {
        let head = u16::from_le_bytes([rest[0], rest[1]]);
        let len = usize::from(rest[2] & 0x0F).min(8);
        let step = Duration::from_millis(u64::from(rest[2] >> 4) * 40);
        rest = &rest[3..];
        let take = len.min(rest.len());
        let (payload, tail) = rest.split_at(take);
        rest = tail;
        let id = CanId::Standard(head & 0x7FF);
        let frame = if head & 0x8000 != 0 {
            Frame::remote(id, len as u8)
        } else {
            Frame::new(id, payload)
        };
        if let Ok(frame) = frame {
            out.push((step, frame));
        }
    }
    out
}

/// Feeds frames to a core, checking that every input yields a bounded number
/// of frames and events and that deadlines are honoured.
fn feed<S: Service>(
    core: &mut S,
    input: &[(Duration, Frame)],
    mut on_frame: impl FnMut(&mut S, Frame),
) {
    let mut now = Instant::from_millis(1);
    for (step, frame) in input {
        now += *step;
        while let Some(t) = core.poll_timeout() {
            if t > now {
                break;
            }
            core.handle_timeout(now);
            drain(core, &mut on_frame);
            if core.poll_timeout().is_some_and(|t| t <= now) {
                panic!("a deadline stays in the past after handle_timeout");
            }
        }
        core.handle_frame(now, frame);
        drain(core, &mut on_frame);
    }
}

fn drain<S: Service>(core: &mut S, on_frame: &mut impl FnMut(&mut S, Frame)) {
    let mut sent = 0;
    while let Some(frame) = core.poll_transmit() {
        sent += 1;
        assert!(
            sent <= MAX_FRAMES_PER_INPUT,
            "more than {MAX_FRAMES_PER_INPUT} frames for one input"
        );
        on_frame(core, frame);
    }
    let mut events = 0;
    while core.poll_event().is_some() {
        events += 1;
        assert!(
            events <= MAX_EVENTS_PER_INPUT,
            "more than {MAX_EVENTS_PER_INPUT} events for one input"
        );
    }
}

/// SDO request codec: parsing never panics, and encoding what was parsed is
/// stable (parse(encode(r)) encodes to the same bytes).
pub fn sdo_request(data: &[u8]) {
    if let Ok(request) = Request::parse(data) {
        let bytes = request.encode();
        let again = Request::parse(&bytes).expect("an encoded request parses");
        assert_eq!(again.encode(), bytes, "{request:?}");
    }
}

/// SDO response codec, as [`sdo_request`].
pub fn sdo_response(data: &[u8]) {
    if let Ok(response) = Response::parse(data) {
        let bytes = response.encode();
        let again = Response::parse(&bytes).expect("an encoded response parses");
        assert_eq!(again.encode(), bytes, "{response:?}");
    }
}

/// Block segments: a parsed segment encodes back to the same 8 bytes.
pub fn block_segment(data: &[u8]) {
    if let Ok(segment) = BlockSegment::parse(data) {
        assert!((1..=127).contains(&segment.seq));
        assert_eq!(&segment.encode()[..], data);
    }
}

fn test_store() -> MemoryStore {
    let mut store = MemoryStore::new();
    store.insert(0x1000, 0, AccessRight::Ro, &[0x92, 0x01, 0x02, 0x00]);
    store.insert(0x2000, 1, AccessRight::Rw, &[0xA5; 300]);
    store.insert(0x2001, 0, AccessRight::Wo, &[0; 2]);
    store
}

const NODE: u8 = 5;

fn channel() -> Channel {
    Channel::default_for(NodeId::new(NODE).unwrap())
}

/// Frames of the input are put on the server's request id (so that they
/// reach it) unless their id already is an SDO id.
fn to_channel(frames: Vec<(Duration, Frame)>, cob: CanId) -> Vec<(Duration, Frame)> {
    frames
        .into_iter()
        .map(|(step, f)| match f.standard_id() {
            Some(id) if !(0x580..=0x67F).contains(&id) && !f.is_remote() => {
                let mut data = [0u8; 8];
                data[..f.len()].copy_from_slice(f.data());
                (step, Frame::with_id(cob, data, f.len() as u8))
            }
            _ => (step, f),
        })
        .collect()
}

/// The SDO server fed arbitrary frames: bounded output, a store that holds
/// only values of allowed size, and the answers are valid SDO frames.
pub fn sdo_server(data: &[u8]) {
    let mut config = ServerConfig::new(channel());
    config.max_download = 1024;
    config.block_size = 4;
    let mut server = SdoServer::new(config, test_store());
    let input = to_channel(frames(data), channel().request);
    feed(&mut server, &input, |_, frame| {
        assert_eq!(frame.id(), channel().response);
        assert_eq!(frame.len(), 8);
    });
    for (index, sub) in [(0x2000, 1), (0x2001, 0)] {
        let len = server.store().get(index, sub).map_or(0, <[u8]>::len);
        assert!(len <= 1024);
    }
}

/// The SDO client running one transfer, chosen by the first input byte, fed
/// arbitrary frames: bounded output and at most one end event per transfer.
pub fn sdo_client(data: &[u8]) {
    let Some((&choice, rest)) = data.split_first() else {
        return;
    };
    let mut config = ClientConfig::new(channel());
    config.max_upload = 512;
    config.block_size = 1 + choice % 8;
    let mut client = SdoClient::new(config);
    let method = [
        Method::Auto,
        Method::Standard,
        Method::Segmented,
        Method::Block,
    ][usize::from(choice >> 6)];
    let now = Instant::from_millis(1);
    let payload = vec![0x3C; usize::from(choice & 0x3F) * 3];
    let started = if choice & 0x20 != 0 {
        client.upload_with(now, 0x2000, 1, method)
    } else {
        client.download_with(now, 0x2000, 1, &payload, method)
    };
    assert!(started.is_ok());
    let input = to_channel(frames(rest), channel().response);
    let mut ends = 0;
    let mut now = now;
    for (step, frame) in &input {
        now += *step;
        if client.poll_timeout().is_some_and(|t| t <= now) {
            client.handle_timeout(now);
        }
        client.handle_frame(now, frame);
        let mut sent = 0;
        while let Some(f) = client.poll_transmit() {
            sent += 1;
            assert!(sent <= MAX_FRAMES_PER_INPUT);
            assert_eq!(f.id(), channel().request);
        }
        while client.poll_event().is_some() {
            ends += 1;
        }
        assert!(ends <= 1, "more than one end event for one transfer");
    }
}

/// NMT, heartbeat and node guarding: parsers and cores on arbitrary frames.
pub fn nmt_and_error_control(data: &[u8]) {
    let input = frames(data);
    for (_, f) in &input {
        let _ = parse_command(f);
        let _ = parse_heartbeat(f);
    }
    feed(&mut NmtMaster::new(), &input, |_, _| {});
    let mut consumer = HeartbeatConsumer::new();
    for node in 1..=8 {
        consumer.monitor(NodeId::new(node).unwrap(), Some(Duration::from_millis(100)));
    }
    feed(&mut consumer, &input, |_, _| {});
    let mut guard = NodeGuard::new();
    guard.guard(
        Instant::from_millis(1),
        NodeId::new(3).unwrap(),
        Duration::from_millis(50),
        core::num::NonZeroU8::new(3).unwrap(),
    );
    feed(&mut guard, &input, |_, _| {});
    feed(
        &mut GuardResponder::new(NodeId::new(3).unwrap()),
        &input,
        |_, _| {},
    );
    let mut slave = NmtSlave::new(NodeId::new(3).unwrap());
    slave.boot_complete();
    feed(&mut slave, &input, |_, _| {});
}

/// EMCY and SYNC: parsers and consumers on arbitrary frames.
pub fn emcy_and_sync(data: &[u8]) {
    let input = frames(data);
    for (_, f) in &input {
        if let Ok(emcy) = Emcy::parse(f.data()) {
            assert_eq!(&emcy.to_bytes()[..], f.data());
        }
        if let Some(Some(counter)) = parse_sync(f) {
            assert_eq!(f.data(), [counter]);
        }
    }
    feed(&mut EmcyConsumer::new(), &input, |_, _| {});
    feed(&mut SyncConsumer::new(), &input, |_, _| {});
}

/// candump lines: any text parses or fails with a reason; what parses writes
/// back in every format to a line that parses to the same frame.
pub fn candump_line(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(Some(line)) = candump::parse_line(text) {
        for format in [Format::Log, Format::Text, Format::Compact] {
            let written = line.display(format).to_string();
            let again = candump::parse_line(&written)
                .unwrap_or_else(|e| panic!("{written:?} ({format:?}) does not parse: {e:?}"))
                .unwrap_or_else(|| panic!("{written:?} ({format:?}) parses to nothing"));
            assert_eq!(again.frame, line.frame, "{written:?}");
        }
    }
}

/// LSS (CiA 305): the request and response codecs are stable, and master
/// and slave fed arbitrary frames stay bounded.
pub fn lss_frames(data: &[u8]) {
    use eds2rust_runtime::lss::proto::{Request as LssRequest, Response as LssResponse};
    use eds2rust_runtime::lss::{BitRate, BitTiming, Identity, LssMaster, LssSlave};
    if let Some(request) = LssRequest::parse(data) {
        let bytes = request.encode();
        assert_eq!(LssRequest::parse(&bytes).map(|r| r.encode()), Some(bytes));
    }
    if let Some(response) = LssResponse::parse(data) {
        let bytes = response.encode();
        assert_eq!(LssResponse::parse(&bytes).map(|r| r.encode()), Some(bytes));
    }
    let input = frames(data);
    let identity = Identity::new(0x0000_0123, 0x4567, 1, 0x89AB);
    feed(
        &mut LssSlave::new(identity, None, BitTiming::standard(BitRate::Kbit250)),
        &input,
        |_, _| {},
    );
    let mut master = LssMaster::new();
    let _ = master.identify_non_configured(Instant::from_millis(1));
    feed(&mut master, &input, |_, _| {});
}

/// The PDO receiver fed arbitrary frames: bounded events, latest data never
/// longer than the watched length.
pub fn pdo_receiver(data: &[u8]) {
    use eds2rust_runtime::pdo::PdoReceiver;
    let mut receiver: PdoReceiver<4> = PdoReceiver::new();
    for (cob, len) in [(0x181u32, 8usize), (0x281, 2), (0x1A0, 0)] {
        receiver
            .watch(
                eds2rust_runtime::pdo::PdoCobId(cob),
                len,
                Some(Duration::from_millis(100)),
            )
            .expect("a valid COB-ID");
    }
    feed(&mut receiver, &frames(data), |_, _| {});
}
