//! Typed SDO access with generated objects: the runtime's blocking SDO
//! client reads LINAK entries over the virtual bus from an SDO server and
//! returns their generated value types; writes go through the generated
//! types of writable entries (writing a read-only one does not compile, see
//! ui/sdo_write_read_only.rs). Raw access stays available beside it.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread;

use eds2rust_drivers::linak_techline::{errors::LinakErrors, od};
use eds2rust_runtime::blocking::{self, Error, SdoClient};
use eds2rust_runtime::od::{AccessRight, Entry, NodeId, Scaled};
use eds2rust_runtime::sdo::client::ClientConfig;
use eds2rust_runtime::sdo::server::{MemoryStore, SdoServer, ServerConfig};
use eds2rust_runtime::sdo::{AbortCode, Channel, SdoError};
use eds2rust_runtime::transport::Clock;
use eds2rust_runtime::transport::virtual_bus::VirtualBus;

fn address<E: Entry>() -> (u16, u8) {
    (E::INDEX, E::SUBINDEX)
}

/// A LINAK-like SDO server at node 32 holding a feedback record (as TPDO1 of
/// the manual's trace `1A 00 06 88 00 31 00 C0` reports it), the command
/// record, the heartbeat time and the hardware version string.
fn linak_server(bus: &VirtualBus, stop: Arc<AtomicBool>) -> thread::JoinHandle<MemoryStore> {
    let mut store = MemoryStore::new();
    let (i, s) = address::<od::feedback::Position>();
    store.insert_fixed(i, s, AccessRight::Ro, &[0x1A, 0x00]);
    let (i, s) = address::<od::feedback::Current>();
    store.insert_fixed(i, s, AccessRight::Ro, &[0x06]);
    let (i, s) = address::<od::feedback::StatusFlags>();
    store.insert_fixed(i, s, AccessRight::Ro, &[0x88]);
    let (i, s) = address::<od::feedback::ErrorCode>();
    store.insert_fixed(i, s, AccessRight::Ro, &[0x01]);
    let (i, s) = address::<od::command::Position>();
    store.insert_fixed(i, s, AccessRight::Rww, &[0xFB, 0xFB]);
    let (i, s) = address::<od::ProducerHeartbeatTime>();
    store.insert_fixed(i, s, AccessRight::Rw, &[0, 0]);
    let (i, s) = address::<od::ManufacturerHardwareVersion>();
    store.insert(i, s, AccessRight::Ro, b"LA36 rev. C");
    serve(bus, stop, NodeId::new(32).unwrap(), store)
}

/// An SDO server of `node` holding `store`, on `bus` in a thread until
/// `stop`; the thread returns the store.
fn serve(
    bus: &VirtualBus,
    stop: Arc<AtomicBool>,
    node: NodeId,
    store: MemoryStore,
) -> thread::JoinHandle<MemoryStore> {
    let mut server = SdoServer::new(ServerConfig::new(Channel::default_for(node)), store);
    let mut port = bus.attach();
    thread::spawn(move || {
        blocking::serve(&mut port, &Clock::new(), &mut server, &stop, None, |_| {}).unwrap();
        server.into_store()
    })
}

#[test]
fn generated_entries_read_and_write_through_the_sdo_client() {
    let bus = VirtualBus::new();
    let stop = Arc::new(AtomicBool::new(false));
    let server = linak_server(&bus, stop.clone());
    let channel = Channel::default_for(NodeId::new(32).unwrap());
    let mut client = SdoClient::new(bus.attach(), ClientConfig::new(channel));

    // Reads give the generated value types.
    let position: od::feedback::PositionValue = client.read::<od::feedback::Position>().unwrap();
    assert_eq!(position.number().map(|n| n.value()), Some(2.6));
    let flags = client.read::<od::feedback::StatusFlags>().unwrap();
    assert!(flags.running_out() && flags.always_set() && !flags.running_in());
    let error = client.read::<od::feedback::ErrorCode>().unwrap();
    assert_eq!(error.kind(), LinakErrors::PowerUpLock);
    assert_eq!(
        client
            .read_string::<od::ManufacturerHardwareVersion>()
            .unwrap(),
        "LA36 rev. C"
    );

    // Writes take them.
    client
        .write::<od::command::Position>(od::command::PositionValue::STOP)
        .unwrap();
    client
        .write::<od::ProducerHeartbeatTime>(od::ProducerHeartbeatTimeValue::from_raw(200))
        .unwrap();
    assert_eq!(
        client.read::<od::command::Position>().unwrap(),
        od::command::PositionValue::STOP
    );

    // Raw access beside the typed one.
    assert_eq!(client.upload(0x1017, 0).unwrap(), [200, 0]);
    client.download(0x1017, 0, &[0xE8, 0x03]).unwrap();
    assert_eq!(
        client.read::<od::ProducerHeartbeatTime>().unwrap().to_raw(),
        1000
    );

    // The server's refusals come back as typed aborts.
    match client.download(0x2001, 1, &[0, 0]) {
        Err(Error::Sdo {
            error: SdoError::RemoteAbort(AbortCode::WriteReadOnly),
            ..
        }) => {}
        other => panic!("writing the read-only feedback position gave {other:?}"),
    }
    match client.upload(0x2003, 0) {
        Err(Error::Sdo {
            error: SdoError::RemoteAbort(AbortCode::ObjectDoesNotExist),
            ..
        }) => {}
        other => panic!("reading a missing object gave {other:?}"),
    }

    stop.store(true, Ordering::Relaxed);
    let store = server.join().unwrap();
    assert_eq!(store.get(0x2000, 1), Some(&[0x03, 0xFB][..]));
}

/// `od::OBJECTS` lists every entry as data: a store built from it alone (the
/// start of a generic device simulator) answers typed reads with the
/// source's defaults, `$NODEID` defaults resolved for the node.
#[test]
fn object_table_fills_an_sdo_store() {
    use eds2rust_drivers::linak_techline::od::OBJECTS;
    use eds2rust_runtime::od::DefaultValue;

    assert!(
        OBJECTS
            .windows(2)
            .all(|w| (w[0].index, w[0].subindex) < (w[1].index, w[1].subindex))
    );
    let position = OBJECTS
        .iter()
        .find(|o| (o.index, o.subindex) == (0x2001, 1))
        .expect("feedback position is listed");
    assert_eq!(position.access, AccessRight::Ro);
    assert_eq!(
        position.data_type,
        eds2rust_runtime::od::DataType::Unsigned16
    );
    assert!(position.pdo_mappable);

    let node = NodeId::new(32).unwrap();
    let mut store = MemoryStore::new();
    for object in OBJECTS {
        let mut buf = [0u8; 8];
        if let Some(len) = object.encode_default(Some(node), &mut buf) {
            store.insert(object.index, object.subindex, object.access, &buf[..len]);
        } else if let Some(DefaultValue::Bytes(bytes)) = object.default {
            store.insert(object.index, object.subindex, object.access, bytes);
        }
    }
    let bus = VirtualBus::new();
    let stop = Arc::new(AtomicBool::new(false));
    let handle = serve(&bus, stop.clone(), node, store);
    let mut client = SdoClient::new(bus.attach(), ClientConfig::new(Channel::default_for(node)));
    assert_eq!(client.read::<od::CobIdEmcy>().unwrap().to_raw(), 0xA0);
    assert_eq!(
        client
            .read::<od::sdo_server_parameter::CobIdClientToServer>()
            .unwrap(),
        od::sdo_server_parameter::CobIdClientToServer::default_for(node)
    );
    assert_eq!(
        client.read::<od::ProducerHeartbeatTime>().unwrap(),
        od::ProducerHeartbeatTime::DEFAULT
    );
    stop.store(true, Ordering::Relaxed);
    handle.join().unwrap();
}

/// The elements of an ARRAY over SDO, in both forms: an element fixed at
/// compile time (`PreDefinedErrorField<1>`) and elements chosen at run time
/// (`Element::<PreDefinedErrorField>`), against an Interroll-like server
/// holding an error history of 8 codes (0x1003, chapter 5.1) and LINAK's
/// consumer heartbeat time (0x1016 sub 1, rw).
#[test]
fn array_elements_read_and_write_in_both_forms() {
    use eds2rust_drivers::interroll_ec5000bi::od::pre_defined_error_field::PreDefinedErrorField;
    use eds2rust_drivers::linak_techline::od::consumer_heartbeat_time::{
        ConsumerHeartbeatTime, ConsumerHeartbeatTimeValue,
    };
    use eds2rust_runtime::od::{Array, Element};

    let bus = VirtualBus::new();
    let stop = Arc::new(AtomicBool::new(false));
    let mut store = MemoryStore::new();
    for sub in PreDefinedErrorField::FIRST..=PreDefinedErrorField::LAST {
        // Code 0x3210 + sub in the low 16 bits of each error field.
        let code = 0x3210u32 + u32::from(sub);
        store.insert_fixed(0x1003, sub, AccessRight::Ro, &code.to_le_bytes());
    }
    store.insert_fixed(0x1016, 1, AccessRight::Rw, &[0, 0, 0, 0]);
    let node = NodeId::new(5).unwrap();
    let server = serve(&bus, stop.clone(), node, store);
    let mut client = SdoClient::new(bus.attach(), ClientConfig::new(Channel::default_for(node)));

    // Compile-time form.
    let newest = client.read::<PreDefinedErrorField<1>>().unwrap();
    assert_eq!(newest.to_raw(), 0x3211);
    // Run-time form: every element in order.
    let codes: Vec<u32> = Element::<PreDefinedErrorField>::all()
        .map(|at| client.read_at(at).unwrap().to_raw())
        .collect();
    assert_eq!(codes, (0x3211..=0x3218).collect::<Vec<u32>>());
    // A sub-index from outside (a user's input) is checked first.
    assert!(Element::<PreDefinedErrorField>::new(9).is_none());

    // Writing an rw element at run time; reading it back at compile time.
    let watch = ConsumerHeartbeatTimeValue::from_raw(0x0001_00C8);
    let first = Element::<ConsumerHeartbeatTime>::new(1).unwrap();
    client.write_at(first, watch).unwrap();
    assert_eq!(client.read::<ConsumerHeartbeatTime<1>>().unwrap(), watch);

    stop.store(true, Ordering::Relaxed);
    let store = server.join().unwrap();
    assert_eq!(store.get(0x1016, 1), Some(&[0xC8, 0x00, 0x01, 0x00][..]));
}
