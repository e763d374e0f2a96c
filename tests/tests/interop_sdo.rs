//! SDO interoperability with python-canopen 2.4.1, over the `peer.py` bridge:
//! our client against python-canopen's SDO server (a LocalNode), and
//! python-canopen's client (a RemoteNode) against our server over a
//! `MemoryStore`. Values are compared byte for byte.
//!
//! One Python process serves every test of this file; each test uses its
//! own node ids, so they run in parallel.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Condvar, Mutex, OnceLock};
use std::thread;
use std::time::{Duration, Instant};

use eds2rust_drivers::linak_techline::od::{
    ManufacturerHardwareVersion, ProducerHeartbeatTime, ProducerHeartbeatTimeValue, identity,
};
use eds2rust_runtime::blocking::{self, SdoClient};
use eds2rust_runtime::od::{AccessRight, NodeId};
use eds2rust_runtime::sdo::client::{self, ClientConfig, ClientEvent, Method};
use eds2rust_runtime::sdo::server::{MemoryStore, SdoServer, ServerConfig, ServerEvent};
use eds2rust_runtime::sdo::{AbortCode, Channel, SdoError};
use eds2rust_runtime::transport::Clock;
use eds2rust_tests::peer::{self, Outcome, PeerPort, PyPeer, hex};
use serde_json::{Value, json};

static PEER: OnceLock<PyPeer> = OnceLock::new();

fn py() -> &'static PyPeer {
    peer::shared(&PEER)
}

/// The sizes every direction and protocol is tried with.
const SIZES: &[usize] = &[0, 1, 2, 3, 4, 5, 6, 7, 8, 13, 14, 15, 100, 889, 4096];

/// Test data: varies from byte to byte, and between sizes.
fn pattern(len: usize) -> Vec<u8> {
    (0..len)
        .map(|i| (i as u8).wrapping_mul(37) ^ (i >> 8) as u8 ^ (len as u8).wrapping_add(0x5A))
        .collect()
}

fn node(id: u8) -> NodeId {
    NodeId::new(id).expect("a valid node id")
}

/// Index of the DOMAIN object holding `SIZES[i]` bytes.
fn index_of(i: usize) -> u16 {
    0x2000 + i as u16
}

/// Creates a python-canopen LocalNode whose DOMAIN objects 0x2000.. hold
/// the sizes of [`SIZES`], plus a read-only UNSIGNED32 at 0x3000, a
/// read-write UNSIGNED16 at 0x3001 and a record 0x3100 with sub 1.
fn python_server(id: u8) {
    let mut objects: Vec<Value> = SIZES
        .iter()
        .enumerate()
        .map(|(i, &len)| {
            json!({"index": index_of(i), "sub": 0, "type": "DOMAIN", "access": "rw",
                   "value": hex(&pattern(len))})
        })
        .collect();
    objects
        .push(json!({"index": 0x3000, "type": "UNSIGNED32", "access": "ro", "value": "78563412"}));
    objects.push(json!({"index": 0x3001, "type": "UNSIGNED16", "access": "rw", "value": "3412"}));
    objects.push(
        json!({"index": 0x3100, "sub": 1, "type": "UNSIGNED8", "access": "rw", "value": "07"}),
    );
    py().command_ok(json!({"op": "local_node", "node": id, "objects": objects}))
        .unwrap_or_else(|e| panic!("{e}"));
}

/// The settings of our clients: the default channel of `id`, a generous
/// timeout (python may be slow on a loaded machine).
fn client_config(id: u8) -> ClientConfig {
    let mut config = ClientConfig::new(Channel::default_for(node(id)));
    config.timeout = Duration::from_secs(1);
    config
}

/// Our blocking client for `id` on a fresh port.
fn our_client(id: u8) -> SdoClient<PeerPort> {
    SdoClient::new(py().port(), client_config(id))
}

/// The SDO error of a failed transfer (any other failure is a test failure).
fn sdo_error<T: std::fmt::Debug>(result: Result<T, blocking::Error>) -> Result<T, SdoError> {
    result.map_err(|e| match e {
        blocking::Error::Sdo { error: e, .. } => e,
        other => panic!("{}", py().failure(&format!("not an SDO error: {other}"))),
    })
}

fn upload(
    ours: &mut SdoClient<PeerPort>,
    index: u16,
    sub: u8,
    method: Method,
) -> Result<Vec<u8>, SdoError> {
    sdo_error(ours.upload_with(index, sub, method))
}

fn download(
    ours: &mut SdoClient<PeerPort>,
    index: u16,
    sub: u8,
    data: &[u8],
    method: Method,
) -> Result<(), SdoError> {
    sdo_error(ours.download_with(index, sub, data, method))
}

fn python_value(id: u8, index: u16, sub: u8) -> Vec<u8> {
    py().command_ok(json!({"op": "get", "node": id, "index": index, "sub": sub}))
        .and_then(|reply| Outcome::of(reply).value())
        .unwrap_or_else(|e| panic!("{e}"))
}

fn python_last_abort(id: u8) -> u64 {
    let reply = py()
        .command_ok(json!({"op": "local_state", "node": id}))
        .unwrap_or_else(|e| panic!("{e}"));
    reply["last_abort"]
        .as_u64()
        .expect("last_abort is a number")
}

// ---------------------------------------------------------------------------
// Our client against python-canopen's server.

#[test]
fn our_client_uploads_from_python_server() {
    const ID: u8 = 0x10;
    python_server(ID);
    let mut ours = our_client(ID);
    for (i, &len) in SIZES.iter().enumerate() {
        for method in [Method::Auto, Method::Standard] {
            let result = upload(&mut ours, index_of(i), 0, method);
            if len == 0 {
                // python-canopen's server refuses to upload an empty value.
                assert_eq!(
                    result,
                    Err(SdoError::RemoteAbort(AbortCode::NoDataAvailable)),
                    "empty upload ({method:?})"
                );
            } else {
                assert_eq!(
                    result.as_deref(),
                    Ok(&pattern(len)[..]),
                    "{len} bytes ({method:?})"
                );
            }
        }
    }
    // A numeric object of a record, by sub-index.
    assert_eq!(upload(&mut ours, 0x3100, 1, Method::Auto), Ok(vec![7]));
}

#[test]
fn our_client_downloads_to_python_server() {
    const ID: u8 = 0x11;
    python_server(ID);
    let mut ours = our_client(ID);
    for (i, &len) in SIZES.iter().enumerate() {
        for (round, method) in [Method::Auto, Method::Segmented].into_iter().enumerate() {
            // Different bytes each round, so a stale value cannot pass.
            let mut data = pattern(len);
            data.iter_mut().for_each(|b| *b ^= 0xA5 ^ round as u8);
            download(&mut ours, index_of(i), 0, &data, method)
                .unwrap_or_else(|e| panic!("download of {len} bytes ({method:?}): {e}"));
            assert_eq!(
                python_value(ID, index_of(i), 0),
                data,
                "{len} bytes ({method:?})"
            );
        }
    }
    download(&mut ours, 0x3001, 0, &[0xCD, 0xAB], Method::Auto).unwrap();
    assert_eq!(python_value(ID, 0x3001, 0), vec![0xCD, 0xAB]);
    download(&mut ours, 0x3100, 1, &[0x42], Method::Segmented).unwrap();
    assert_eq!(python_value(ID, 0x3100, 1), vec![0x42]);
}

#[test]
fn python_server_aborts_reach_our_client() {
    const ID: u8 = 0x12;
    python_server(ID);
    let mut ours = our_client(ID);
    assert_eq!(
        upload(&mut ours, 0x5FFF, 0, Method::Auto),
        Err(SdoError::RemoteAbort(AbortCode::ObjectDoesNotExist))
    );
    assert_eq!(
        upload(&mut ours, 0x3100, 9, Method::Auto),
        Err(SdoError::RemoteAbort(AbortCode::SubindexDoesNotExist))
    );
    assert_eq!(
        download(&mut ours, 0x3000, 0, &[1, 2, 3, 4], Method::Auto),
        Err(SdoError::RemoteAbort(AbortCode::WriteReadOnly))
    );
    assert_eq!(
        download(&mut ours, 0x5FFF, 0, &pattern(20), Method::Auto),
        Err(SdoError::RemoteAbort(AbortCode::ObjectDoesNotExist))
    );
    // A UNSIGNED16 written with 4 bytes.
    assert_eq!(
        download(&mut ours, 0x3001, 0, &[1, 2, 3, 4], Method::Auto),
        Err(SdoError::RemoteAbort(AbortCode::LengthMismatch))
    );
    // python-canopen's server has no block transfers: it refuses block
    // downloads, and answers a block upload request with a standard upload
    // (expedited or segmented), which our client follows.
    assert_eq!(
        download(&mut ours, index_of(12), 0, &pattern(100), Method::Block),
        Err(SdoError::RemoteAbort(AbortCode::InvalidCommand))
    );
    for i in [1, 4, 5, 12] {
        assert_eq!(
            upload(&mut ours, index_of(i), 0, Method::Block),
            Ok(pattern(SIZES[i])),
            "block upload of {} bytes",
            SIZES[i]
        );
    }
    // Nothing hangs: the next transfer works.
    assert_eq!(
        upload(&mut ours, index_of(12), 0, Method::Auto),
        Ok(pattern(100))
    );
}

#[test]
fn our_client_aborts_reach_python_server() {
    const ID: u8 = 0x13;
    python_server(ID);
    let big = SIZES.iter().position(|&len| len == 889).unwrap();
    let small = SIZES.iter().position(|&len| len == 100).unwrap();

    // The server announces more than we accept: abort before any segment.
    let mut config = client_config(ID);
    config.max_upload = 500;
    let mut ours = SdoClient::new(py().port(), config);
    assert_eq!(
        upload(&mut ours, index_of(big), 0, Method::Auto),
        Err(SdoError::LocalAbort(AbortCode::OutOfMemory))
    );
    assert_python_saw_abort(ID, AbortCode::OutOfMemory);
    assert_eq!(
        upload(&mut ours, index_of(small), 0, Method::Auto),
        Ok(pattern(100))
    );

    // An abort in the middle of a segmented upload, with the sans-IO core.
    let mut port = py().port();
    let clock = Clock::new();
    let mut core = client::SdoClient::new(client_config(ID));
    core.upload(clock.now(), index_of(big), 0).unwrap();
    for _ in 0..10 {
        // One frame from python's server per step.
        let events = peer::step(&mut port, &clock, &mut core, Duration::from_secs(1))
            .unwrap_or_else(|e| panic!("{e}"));
        assert!(events.is_empty(), "the transfer ended early: {events:?}");
    }
    core.abort(AbortCode::CannotTransfer);
    let end = peer::run_until(&mut port, &clock, &mut core, Duration::from_secs(5), Some)
        .unwrap_or_else(|e| panic!("{}", py().failure(&e)));
    assert_eq!(
        end,
        ClientEvent::Failed {
            index: index_of(big),
            sub: 0,
            error: SdoError::LocalAbort(AbortCode::CannotTransfer)
        }
    );
    assert_python_saw_abort(ID, AbortCode::CannotTransfer);
    // The answer to our last segment request may have crossed the abort;
    // it must not be taken for the answer to the next request.
    py().settle(&mut port).unwrap_or_else(|e| panic!("{e}"));
    let mut ours = SdoClient::new(port, client_config(ID));
    assert_eq!(
        upload(&mut ours, index_of(big), 0, Method::Auto),
        Ok(pattern(889))
    );
}

#[test]
fn our_typed_access_to_python_node() {
    // A python node with the identity and heartbeat objects of the LINAK
    // TECHLINE driver; our client reads and writes them through the
    // generated entry types.
    const ID: u8 = 0x14;
    let objects = json!([
        {"index": 0x1009, "type": "VISIBLE_STRING", "access": "ro",
         "value": hex(b"10LAXXCA-A-0")},
        {"index": 0x1017, "type": "UNSIGNED16", "access": "rw", "value": "0000"},
        {"index": 0x1018, "sub": 1, "type": "UNSIGNED32", "access": "ro", "value": "43020000"},
        {"index": 0x1018, "sub": 2, "type": "UNSIGNED32", "access": "ro", "value": "78563412"},
    ]);
    py().command_ok(json!({"op": "local_node", "node": ID, "objects": objects}))
        .unwrap_or_else(|e| panic!("{e}"));
    let mut ours = our_client(ID);
    assert_eq!(
        ours.read_string::<ManufacturerHardwareVersion>().unwrap(),
        "10LAXXCA-A-0"
    );
    assert_eq!(ours.read::<identity::VendorId>().unwrap(), 0x0243);
    assert_eq!(ours.read::<identity::ProductCode>().unwrap(), 0x1234_5678);
    ours.write::<ProducerHeartbeatTime>(ProducerHeartbeatTimeValue(1000))
        .unwrap();
    assert_eq!(python_value(ID, 0x1017, 0), vec![0xE8, 0x03]);
    assert_eq!(
        ours.read::<ProducerHeartbeatTime>().unwrap(),
        ProducerHeartbeatTimeValue(1000)
    );
    // python started its heartbeat producer: stop it again.
    ours.write::<ProducerHeartbeatTime>(ProducerHeartbeatTimeValue(0))
        .unwrap();
}

/// Checks that python's server received our abort `code` (once it handled
/// every frame sent so far).
fn assert_python_saw_abort(id: u8, code: AbortCode) {
    py().barrier().unwrap_or_else(|e| panic!("{e}"));
    let last = python_last_abort(id);
    assert_eq!(
        last,
        u64::from(code.code()),
        "python's server last saw abort {last:#X}, not {code}"
    );
}

// ---------------------------------------------------------------------------
// python-canopen's client against our server.

/// Our server for `id` over a store holding the sizes of [`SIZES`] at
/// 0x2000.., a read-only UNSIGNED32 at 0x3000 and a write-only one at 0x3002.
fn our_server(id: u8) -> SdoServer<MemoryStore> {
    let mut store = MemoryStore::new();
    for (i, &len) in SIZES.iter().enumerate() {
        store.insert(index_of(i), 0, AccessRight::Rw, &pattern(len));
    }
    store.insert_fixed(0x3000, 0, AccessRight::Ro, &[0x78, 0x56, 0x34, 0x12]);
    store.insert_fixed(0x3002, 0, AccessRight::Wo, &[0; 4]);
    let mut config = ServerConfig::new(Channel::default_for(node(id)));
    // Generous: python may be slow on a loaded machine.
    config.timeout = Duration::from_secs(2);
    SdoServer::new(config, store)
}

/// Our server, served on a port of the peer while python runs commands.
struct Served {
    port: PeerPort,
    clock: Clock,
    server: SdoServer<MemoryStore>,
}

impl Served {
    fn new(id: u8) -> Served {
        Served {
            port: py().port(),
            clock: Clock::new(),
            server: our_server(id),
        }
    }

    /// Runs `command` on python while the runtime's `serve` runs our server
    /// in a thread; returns python's outcome and our server's events once
    /// our side ended its transfer too (every transfer ends with one event).
    fn run(&mut self, command: Value) -> (Outcome, Vec<ServerEvent>) {
        let text = command.to_string();
        let stop = AtomicBool::new(false);
        let events = Mutex::new(Vec::new());
        let changed = Condvar::new();
        let Served {
            port,
            clock,
            server,
        } = self;
        let (reply, served) = thread::scope(|scope| {
            let serving = scope.spawn(|| {
                let deadline = Instant::now() + Duration::from_secs(30);
                blocking::serve(port, clock, server, &stop, Some(deadline), |event| {
                    events.lock().unwrap().push(event);
                    changed.notify_all();
                })
            });
            let reply = py().command(command);
            // Our server's event may come after python's reply (the end of
            // a block upload is python's last frame).
            let guard = events.lock().unwrap();
            let _ = changed
                .wait_timeout_while(guard, Duration::from_secs(5), |events| events.is_empty())
                .unwrap();
            stop.store(true, Ordering::Relaxed);
            (reply, serving.join().expect("the serving thread panicked"))
        });
        let events = events.into_inner().unwrap();
        let reply = reply.unwrap_or_else(|e| panic!("{text}: {e}"));
        served.unwrap_or_else(|e| panic!("{}", py().failure(&format!("{text}: serving: {e}"))));
        assert!(
            !events.is_empty() && self.server.is_idle(),
            "{}",
            py().failure(&format!(
                "{text}: our server did not finish; events {events:?}"
            ))
        );
        (Outcome::of(reply), events)
    }

    fn stored(&self, index: u16) -> Vec<u8> {
        self.server
            .store()
            .get(index, 0)
            .expect("object exists")
            .to_vec()
    }
}

fn upload_cmd(id: u8, index: u16, block: Option<bool>) -> Value {
    match block {
        None => json!({"op": "upload", "node": id, "index": index, "sub": 0}),
        Some(crc) => json!({"op": "upload", "node": id, "index": index, "sub": 0,
                             "block": true, "crc": crc}),
    }
}

/// Our server reported `event` (among its `events`).
fn assert_reported(events: &[ServerEvent], event: ServerEvent, what: &str) {
    assert!(events.contains(&event), "{what}: our events {events:?}");
}

fn python_uploads(id: u8, block: Option<bool>) {
    let mut served = Served::new(id);
    for (i, &len) in SIZES.iter().enumerate() {
        let (outcome, events) = served.run(upload_cmd(id, index_of(i), block));
        let what = format!("{len} bytes, block {block:?}");
        assert_eq!(
            outcome
                .value()
                .unwrap_or_else(|e| panic!("{}", py().failure(&format!("{what}: {e}")))),
            pattern(len),
            "{what}"
        );
        let sub = 0;
        let index = index_of(i);
        assert_reported(&events, ServerEvent::Uploaded { index, sub, len }, &what);
    }
}

fn python_downloads(id: u8, mode: Value) {
    let mut served = Served::new(id);
    for (i, &len) in SIZES.iter().enumerate() {
        // An empty block download from python-canopen has no segment at all
        // (the end request follows the initiate); our server accepts that.
        let mut data = pattern(len);
        data.iter_mut().for_each(|b| *b ^= 0x3C);
        let mut command = json!({"op": "download", "node": id, "index": index_of(i), "sub": 0,
                                 "value": hex(&data)});
        if let (Some(command), Some(mode)) = (command.as_object_mut(), mode.as_object()) {
            command.extend(mode.clone());
        }
        let what = format!("{len} bytes, {mode}");
        let (outcome, events) = served.run(command);
        assert!(
            matches!(outcome, Outcome::Done(_)),
            "{}",
            py().failure(&format!("{what}: {outcome:?}; our events {events:?}"))
        );
        assert_eq!(served.stored(index_of(i)), data, "{what}");
        let sub = 0;
        let index = index_of(i);
        assert_reported(&events, ServerEvent::Downloaded { index, sub, len }, &what);
    }
}

#[test]
fn python_uploads_from_our_server_expedited_and_segmented() {
    python_uploads(0x20, None);
}

#[test]
fn python_block_uploads_from_our_server_with_crc() {
    python_uploads(0x21, Some(true));
}

#[test]
fn python_block_uploads_from_our_server_without_crc() {
    python_uploads(0x22, Some(false));
}

#[test]
fn python_downloads_to_our_server_expedited_and_segmented() {
    python_downloads(0x23, json!({}));
}

#[test]
fn python_forced_segmented_downloads_to_our_server() {
    python_downloads(0x24, json!({"segmented": true}));
}

#[test]
fn python_block_downloads_to_our_server_with_crc() {
    python_downloads(0x25, json!({"block": true, "crc": true}));
}

#[test]
fn python_block_downloads_to_our_server_without_crc() {
    python_downloads(0x26, json!({"block": true, "crc": false}));
}

#[test]
fn our_server_aborts_reach_python_client() {
    const ID: u8 = 0x27;
    let mut served = Served::new(ID);
    let missing = u64::from(AbortCode::ObjectDoesNotExist.code());
    let read_only = u64::from(AbortCode::WriteReadOnly.code());
    let write_only = u64::from(AbortCode::ReadWriteOnly.code());
    let cases = [
        (upload_cmd(ID, 0x5FFF, None), missing),
        (upload_cmd(ID, 0x5FFF, Some(true)), missing),
        (upload_cmd(ID, 0x3002, None), write_only),
        (
            json!({"op": "download", "node": ID, "index": 0x3000, "value": "01020304"}),
            read_only,
        ),
        (
            json!({"op": "download", "node": ID, "index": 0x3000, "value": hex(&pattern(30))}),
            read_only,
        ),
        (
            json!({"op": "download", "node": ID, "index": 0x3000, "value": "01020304",
                "block": true}),
            read_only,
        ),
        (
            json!({"op": "download", "node": ID, "index": 0x5FFF, "value": "01",
                "segmented": true}),
            missing,
        ),
    ];
    for (command, code) in cases {
        let text = command.to_string();
        let (outcome, events) = served.run(command);
        assert_eq!(outcome, Outcome::Abort(code as u32), "{text}");
        assert!(
            events.iter().any(
                |e| matches!(e, ServerEvent::Failed { error: SdoError::LocalAbort(c), .. }
                if u64::from(c.code()) == code)
            ),
            "{text}: our events {events:?}"
        );
    }
    assert_eq!(served.stored(0x3000), vec![0x78, 0x56, 0x34, 0x12]);
    // The server still serves.
    let (outcome, _) = served.run(upload_cmd(ID, 0x3000, None));
    assert_eq!(outcome.value(), Ok(vec![0x78, 0x56, 0x34, 0x12]));
}
