//! The generic simulated device without a model, on the README's example
//! EDS (eds/example.eds: limits, write-only and read-only entries, one RPDO
//! and one TPDO) and on the Zimmer table (store and restore signatures),
//! against the runtime's master in virtual time. Expected frames and abort
//! codes are written from CiA 301 and CiA 305.

use std::time::Duration;

use eds2rust_drivers::{example, zimmer_acs};
use eds2rust_runtime::lss::{BitRate, Identity, LssState};
use eds2rust_runtime::master::{Master, MasterEvent};
use eds2rust_runtime::nmt::{NmtCommand, NmtState, NmtTarget};
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::sdo::SdoError;
use eds2rust_runtime::sdo::abort::AbortCode;
use eds2rust_runtime::{CanId, Frame, Instant};
use eds2rust_sim::bench::Bench;
use eds2rust_sim::{Device, DeviceConfig, SimEvent};

fn node(n: u8) -> NodeId {
    NodeId::new(n).expect("node id")
}

fn frame(id: u16, data: &[u8]) -> Frame {
    Frame::new(CanId::Standard(id), data).expect("frame")
}

fn example_bench() -> Bench<()> {
    let device = Device::new(
        example::od::OBJECTS,
        DeviceConfig::node(node(5)),
        (),
        Instant::ZERO,
    );
    // The master's heartbeat is off, to keep the traces short.
    Bench::new(Master::new(node(1), None), device, Instant::ZERO)
}

fn abort(code: AbortCode) -> Result<(), SdoError> {
    Err(SdoError::RemoteAbort(code))
}

/// The master's LSS switch state global to `state`.
fn switch_global<B: eds2rust_sim::Behaviour>(b: &mut Bench<B>, state: LssState) {
    let now = b.now();
    b.master.lss.switch_global(now, state).expect("idle");
}

/// The master sends NMT `command` to `target` (at its next step).
fn nmt<B: eds2rust_sim::Behaviour>(b: &mut Bench<B>, command: NmtCommand, target: NodeId) {
    b.master
        .nmt
        .send(command, NmtTarget::Node(target))
        .expect("queue");
}

#[test]
fn boots_and_produces_the_heartbeat_of_0x1017() {
    let mut b = example_bench();
    b.run_for(Duration::from_millis(2500));
    // Boot-up, then the default producer time of 1000 ms, pre-operational.
    // (701#00 is the master's own boot-up.)
    assert_eq!(b.trace_lines(), ["701#00", "705#00", "705#7F", "705#7F"]);
    assert_eq!(b.trace[2].0, Instant::from_micros(1_000_000));
    // 0x1017 = 50 ms (within its limits 0..=65000): heartbeats follow it.
    b.download(node(5), 0x1017, 0, &[50, 0]).expect("0x1017");
    let start = b.trace.len();
    b.run_for(Duration::from_millis(200));
    let beats = b.trace[start..]
        .iter()
        .filter(|(_, f)| f.to_string() == "705#7F")
        .count();
    assert_eq!(beats, 4);
}

#[test]
fn sdo_writes_are_checked_for_access_type_and_limits() {
    let mut b = example_bench();
    let n = node(5);
    // Access rights: write-only, read-only, missing index and subindex.
    for (index, sub, code) in [
        (0x2001, 0, AbortCode::ReadWriteOnly),
        (0x3000, 0, AbortCode::ObjectDoesNotExist),
        (0x1018, 9, AbortCode::SubindexDoesNotExist),
    ] {
        let read = b.upload(n, index, sub).map(drop);
        assert_eq!(read, abort(code), "read {index:#06X}/{sub}");
    }
    let (half, big) = (0.5f32.to_le_bytes(), 100.5f32.to_le_bytes());
    for (index, sub, data, code) in [
        (0x6041, 0, &[0, 0][..], AbortCode::WriteReadOnly),
        (0x1018, 1, &[0; 4], AbortCode::WriteReadOnly),
        // Type: 0x6060 is INTEGER8.
        (0x6060, 0, &[1, 0], AbortCode::LengthTooHigh),
        (0x1017, 0, &[1], AbortCode::LengthTooLow),
        // Limits: 0x6060 is -4..=10, 0x2000 (REAL32) 1.0..=100.0.
        (0x6060, 0, &[11], AbortCode::ValueTooHigh),
        (0x6060, 0, &[(-5i8) as u8], AbortCode::ValueTooLow),
        (0x2000, 0, &half, AbortCode::ValueTooLow),
        (0x2000, 0, &big, AbortCode::ValueTooHigh),
    ] {
        let write = b.download(n, index, sub, data);
        assert_eq!(write, abort(code), "write {data:?} to {index:#06X}/{sub}");
    }
    b.download(n, 0x6060, 0, &[(-4i8) as u8])
        .expect("-4 is the low limit");
    b.download(n, 0x2000, 0, &50.0f32.to_le_bytes())
        .expect("50.0");
    assert_eq!(b.upload(n, 0x2000, 0).expect("read"), 50.0f32.to_le_bytes());
    // A refused write leaves the old value.
    assert_eq!(b.upload(n, 0x6060, 0).expect("read"), [0xFC]);
    // Write-only entries take writes.
    b.download(n, 0x2001, 0, &[1]).expect("write-only");
}

#[test]
fn pdo_mapping_follows_the_cia_301_order_and_rules() {
    let mut b = example_bench();
    let n = node(5);
    // Mapping while the TPDO is valid: refused.
    assert_eq!(
        b.download(n, 0x1A00, 0, &[0]),
        abort(AbortCode::CannotTransferDeviceState)
    );
    // Changing the COB-ID of a valid PDO: refused.
    assert_eq!(
        b.download(n, 0x1800, 1, &0x285u32.to_le_bytes()),
        abort(AbortCode::InvalidValue)
    );
    b.download(n, 0x1800, 1, &0x8000_0185u32.to_le_bytes())
        .expect("disable");
    // Entries only while sub 0 is 0.
    assert_eq!(
        b.download(n, 0x1A00, 1, &0x6064_0020u32.to_le_bytes()),
        abort(AbortCode::CannotTransferDeviceState)
    );
    b.download(n, 0x1A00, 0, &[0]).expect("sub 0 = 0");
    // Not mappable (0x2000), wrong length (0x6064 is 32 bits), write-only
    // (0x2001) into a TPDO: all "cannot be mapped".
    for entry in [0x2000_0020u32, 0x6064_0010, 0x2001_0008] {
        assert_eq!(
            b.download(n, 0x1A00, 1, &entry.to_le_bytes()),
            abort(AbortCode::CannotMap),
            "{entry:#010X}"
        );
    }
    b.download(n, 0x1A00, 1, &0x6064_0020u32.to_le_bytes())
        .expect("entry 1");
    b.download(n, 0x1A00, 2, &0x6041_0010u32.to_le_bytes())
        .expect("entry 2");
    b.download(n, 0x1A00, 3, &0x6064_0020u32.to_le_bytes())
        .expect("entry 3");
    // 32 + 16 + 32 bits > 64.
    assert_eq!(
        b.download(n, 0x1A00, 0, &[3]),
        abort(AbortCode::PdoLengthExceeded)
    );
    b.download(n, 0x1A00, 0, &[2]).expect("sub 0 = 2");
    b.download(n, 0x1800, 1, &0x0000_0185u32.to_le_bytes())
        .expect("enable");
    // Operational: the new layout goes out at once, then on the 100 ms
    // event timer: position (0), statusword (0).
    nmt(&mut b, NmtCommand::Start, n);
    b.run_for(Duration::from_millis(150));
    let tpdos: Vec<String> = b
        .trace_lines()
        .into_iter()
        .filter(|l| l.starts_with("185#"))
        .collect();
    assert_eq!(tpdos, ["185#000000000000", "185#000000000000"]);
}

#[test]
fn rpdos_write_the_mapped_entries_and_length_errors_raise_emcy() {
    let mut b = example_bench();
    nmt(&mut b, NmtCommand::Start, node(5));
    b.run_for(Duration::from_millis(1));
    // RPDO1: controlword 0x000F, target position 1000.
    b.inject(&frame(0x205, &[0x0F, 0x00, 0xE8, 0x03, 0x00, 0x00]));
    assert_eq!(b.device.table().get(0x6040, 0), Some(&[0x0F, 0x00][..]));
    assert_eq!(
        b.device.table().get(0x607A, 0),
        Some(&[0xE8, 0x03, 0, 0][..])
    );
    let written: Vec<_> = b
        .device_events
        .iter()
        .filter_map(|e| match e {
            SimEvent::Written { index, sub } => Some((*index, *sub)),
            _ => None,
        })
        .collect();
    assert_eq!(written, [(0x6040, 0), (0x607A, 0)]);
    // Too short: not processed, EMCY 0x8210 with the error register (0).
    b.inject(&frame(0x205, &[0x06, 0x00]));
    assert_eq!(b.device.table().get(0x6040, 0), Some(&[0x0F, 0x00][..]));
    assert_eq!(
        b.trace_lines().last().map(String::as_str),
        Some("085#1082000000000000")
    );
    // Too long: processed, EMCY 0x8220.
    b.inject(&frame(0x205, &[0x06, 0x00, 0, 0, 0, 0, 0xAA]));
    assert_eq!(b.device.table().get(0x6040, 0), Some(&[0x06, 0x00][..]));
    assert_eq!(
        b.trace_lines().last().map(String::as_str),
        Some("085#2082000000000000")
    );
    // Pre-operational: RPDOs are ignored.
    nmt(&mut b, NmtCommand::EnterPreOperational, node(5));
    b.run_for(Duration::from_millis(1));
    b.inject(&frame(0x205, &[0x07, 0x00, 0, 0, 0, 0]));
    assert_eq!(b.device.table().get(0x6040, 0), Some(&[0x06, 0x00][..]));
}

#[test]
fn store_and_restore_signatures_survive_a_power_cycle() {
    let device = Device::new(
        zimmer_acs::od::OBJECTS,
        DeviceConfig::node(node(40)),
        (),
        Instant::ZERO,
    );
    let mut b = Bench::new(Master::new(node(1), None), device, Instant::ZERO);
    let n = node(40);
    // Producer heartbeat time, a plain rw entry.
    b.download(n, 0x1017, 0, &[0x2C, 0x01])
        .expect("0x1017 = 300");
    // A wrong signature is refused with 0x08000020.
    assert_eq!(
        b.download(n, 0x1010, 1, b"evas"),
        abort(AbortCode::CannotTransfer)
    );
    // "save" is 0x65766173: on the bus 73 61 76 65.
    b.download(n, 0x1010, 1, b"save").expect("save");
    b.download(n, 0x1017, 0, &[0x64, 0x00])
        .expect("0x1017 = 100, not saved");
    b.device.power_cycle(b.now());
    b.run_for(Duration::from_millis(1));
    assert_eq!(b.upload(n, 0x1017, 0).expect("read"), [0x2C, 0x01]);
    // "load" (0x64616F6C: 6C 6F 61 64): defaults after the next power-on
    // only (Zimmer 11.5).
    b.download(n, 0x1011, 1, b"load").expect("load");
    assert_eq!(b.upload(n, 0x1017, 0).expect("read"), [0x2C, 0x01]);
    b.device.power_cycle(b.now());
    b.run_for(Duration::from_millis(1));
    // The table gives 0x1017 no default: a fresh device starts at 0.
    assert_eq!(
        b.device.table().info(0x1017, 0).and_then(|i| i.default),
        None
    );
    assert_eq!(b.upload(n, 0x1017, 0).expect("read"), [0, 0]);
}

#[test]
fn an_unconfigured_lss_slave_gets_its_node_id_and_moves_its_sdo_server() {
    let identity = Identity::new(0xE2D, 1, 0x0001_0000, 77);
    let config = DeviceConfig {
        node: None,
        lss: Some(identity),
        bit_rate: BitRate::Kbit250,
    };
    let device = Device::new(example::od::OBJECTS, config, (), Instant::ZERO);
    let mut b = Bench::new(Master::new(node(1), None), device, Instant::ZERO);
    b.run_for(Duration::from_millis(100));
    // Unconfigured: no boot-up, no heartbeat (701#00 is the master's).
    assert_eq!(b.trace_lines(), ["701#00"]);
    b.trace.clear();
    switch_global(&mut b, LssState::Configuration);
    b.run_for(Duration::from_millis(1));
    let now = b.now();
    b.master.lss.configure_node_id(now, node(9)).expect("idle");
    assert!(b.run_until(Duration::from_millis(200), |e| matches!(
        e,
        MasterEvent::Lss(_)
    )));
    switch_global(&mut b, LssState::Waiting);
    // CiA 305: an unconfigured slave that got a node id resets its
    // communication by itself when switched back to waiting.
    b.run_for(Duration::from_millis(1));
    assert_eq!(
        b.trace_lines(),
        [
            "7E5#0401000000000000", // switch state global: configuration
            "7E5#1109000000000000", // configure node id 9
            "7E4#1100000000000000", // ... success
            "7E5#0400000000000000", // switch state global: waiting
            "709#00",               // boot-up as node 9
        ]
    );
    assert_eq!(b.device.node(), Some(node(9)));
    assert_eq!(b.device.nmt_state(), NmtState::PreOperational);
    let vendor = b.upload(node(9), 0x1018, 1).expect("vendor id");
    assert_eq!(vendor, example::VENDOR_ID.to_le_bytes());
}

/// An additional server SDO (0x1201) configured over the default channel
/// with 29-bit COB-IDs (bit 29 set): the device then answers on it with
/// extended frames, as well as on its default channel.
#[test]
fn an_additional_sdo_channel_with_29_bit_ids_is_served() {
    use eds2rust_runtime::od::{AccessRight, DataType, DefaultValue, Number, ObjectInfo};
    use eds2rust_runtime::sdo::Channel;
    use eds2rust_runtime::sdo::client::ClientConfig;

    let record = |sub, name, access, default: u32| {
        let data_type = if sub == 0 {
            DataType::Unsigned8
        } else {
            DataType::Unsigned32
        };
        ObjectInfo::new(0x1201, sub, name, data_type, access, false)
            .with_default(DefaultValue::Number(Number::Int(i128::from(default))))
    };
    let mut table: Vec<ObjectInfo> = example::od::OBJECTS.to_vec();
    table.extend([
        record(0, "Highest sub-index supported", AccessRight::Const, 2),
        // Not valid (bit 31) until configured.
        record(1, "COB-ID client to server", AccessRight::Rw, 0x8000_0000),
        record(2, "COB-ID server to client", AccessRight::Rw, 0x8000_0000),
    ]);
    table.sort_by_key(|o| (o.index, o.subindex));
    let table: &'static [ObjectInfo] = Box::leak(table.into_boxed_slice());
    let device = Device::new(table, DeviceConfig::node(node(5)), (), Instant::ZERO);
    let mut b = Bench::new(Master::new(node(1), None), device, Instant::ZERO);
    b.run_for(Duration::from_millis(10));

    // The master reaches the second channel through a client of its own,
    // kept under an unused node id.
    let extended = Channel::extended(0x1ABC_0605, 0x1ABC_0585);
    let via = node(100);
    b.master.add_sdo_client(via, ClientConfig::new(extended));
    // Not configured yet: nobody answers on the 29-bit ids.
    assert_eq!(b.upload(via, 0x1000, 0), Err(SdoError::Timeout));

    let (request, response) = extended.cob_ids();
    assert_eq!((request, response), (0x3ABC_0605, 0x3ABC_0585));
    b.download(node(5), 0x1201, 2, &response.to_le_bytes())
        .expect("0x1201.2");
    b.download(node(5), 0x1201, 1, &request.to_le_bytes())
        .expect("0x1201.1");
    let device_type = b.upload(node(5), 0x1000, 0).expect("default channel");
    let start = b.trace.len();
    assert_eq!(
        b.upload(via, 0x1000, 0).expect("29-bit channel"),
        device_type
    );
    let ids: Vec<CanId> = b.trace[start..].iter().map(|(_, f)| f.id()).collect();
    assert_eq!(
        ids,
        [CanId::Extended(0x1ABC_0605), CanId::Extended(0x1ABC_0585)]
    );
    // Marked not valid again: the channel is gone.
    b.download(node(5), 0x1201, 1, &(request | 0x8000_0000).to_le_bytes())
        .expect("0x1201.1");
    assert_eq!(b.upload(via, 0x1000, 0), Err(SdoError::Timeout));
}
