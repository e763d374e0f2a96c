//! The live commands on the in-process virtual bus against the seed-device
//! simulators (eds2rust-sim): the same code as over SocketCAN, only the
//! bus differs (tests/live_vcan.rs runs the binary over vcan in the VM).

use std::path::PathBuf;
use std::time::Duration;

use eds2rust_runtime::lss::Identity;
use eds2rust_runtime::transport::virtual_bus::VirtualBus;
use eds2rust_sim::models::{interroll_ec5000bi, linak_techline, zimmer_acs};
use eds2rust_sim::{Behaviour, Device, DeviceConfig};

use super::bus::LiveBus;
use super::*;
use crate::served::Served;

fn eds(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../eds")
        .join(name)
}

fn bus_args(timeout_ms: u64) -> BusArgs {
    BusArgs {
        iface: None,
        timeout: Duration::from_millis(timeout_ms),
    }
}

/// A simulator in a thread on a virtual bus; every [`Sim::bus`] is a new
/// port of that bus, so that several commands talk to one device.
struct Sim {
    bus: VirtualBus,
    _served: Served,
}

impl Sim {
    fn start<B>(device: impl FnOnce(eds2rust_runtime::Instant) -> Device<B>) -> Sim
    where
        B: Behaviour + Send + 'static,
        B::Event: Send,
    {
        let bus = VirtualBus::new();
        let served = Served::booted(bus.attach(), device);
        Sim {
            bus,
            _served: served,
        }
    }

    fn bus(&self) -> LiveBus {
        LiveBus::new(Box::new(self.bus.attach()))
    }
}

fn run(f: impl FnOnce(&mut Vec<u8>) -> Result<(), LiveError>) -> (String, Result<(), LiveError>) {
    let mut out = Vec::new();
    let r = f(&mut out);
    (String::from_utf8(out).unwrap(), r)
}

/// A fresh scratch directory of this test process (`tag` tells the tests
/// apart).
fn scratch(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("eds2rust-live-{tag}{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `od upload` of the Zimmer drive at `node` into `dcf`, without DOMAINs.
fn upload_args(bus: BusArgs, node: u8, dcf: &std::path::Path) -> backup::UploadArgs {
    backup::UploadArgs {
        bus,
        node,
        od: eds("zimmer_acs.yaml"),
        output: Some(dcf.to_path_buf()),
        domains: false,
    }
}

/// `od download` of `dcf` to the node it names, not verbose.
fn download_args(dry_run: bool, dcf: PathBuf) -> backup::DownloadArgs {
    backup::DownloadArgs {
        bus: bus_args(500),
        node: None,
        dry_run,
        verbose: false,
        dcf,
    }
}

fn zimmer() -> Sim {
    Sim::start(zimmer_acs::simulator)
}

/// Node `node` on the bus (500 ms timeout), with `od` (a file in eds/).
fn to(node: u8, od: Option<&str>) -> sdo::NodeArgs {
    sdo::NodeArgs {
        bus: bus_args(500),
        node,
        od: od.map(eds),
    }
}

/// `sdo write` of `value` to `object` without `--verify`.
fn write_args(
    to: sdo::NodeArgs,
    ty: Option<eds2rust::ir::DataType>,
    object: &str,
    value: &str,
) -> sdo::WriteArgs {
    sdo::WriteArgs {
        to,
        ty,
        verify: false,
        object: object.into(),
        value: value.into(),
    }
}

fn read_args(node: u8, od: Option<&str>, objects: &[&str]) -> sdo::ReadArgs {
    sdo::ReadArgs {
        to: to(node, od),
        ty: None,
        quiet: false,
        objects: objects.iter().map(|s| s.to_string()).collect(),
    }
}

#[test]
fn sdo_read_typed_raw_and_whole_records() {
    let sim = zimmer();
    let a = read_args(
        40,
        Some("zimmer_acs.yaml"),
        &["Statusword", "0x6060", "identity"],
    );
    let (out, r) = run(|o| sdo::read(|| Ok(sim.bus()), &a, o));
    r.unwrap();
    let lines: Vec<&str> = out.lines().collect();
    assert!(lines[0].starts_with("0x6041 Statusword = "), "{out}");
    assert!(lines[0].contains("state \""), "{out}");
    assert_eq!(
        lines[1],
        "0x6060 Modes of operation = 1 \"profile position\""
    );
    assert_eq!(lines.len(), 2 + 4, "{out}");
    assert!(
        lines[2].starts_with("0x1018 Identity object.Highest sub-index supported = 3 (0x03)"),
        "{out}"
    );
}

#[test]
fn sdo_read_raw_and_quiet() {
    let sim = zimmer();
    let mut a = read_args(40, None, &["0x6060", "0x1018sub0"]);
    let (out, r) = run(|o| sdo::read(|| Ok(sim.bus()), &a, o));
    r.unwrap();
    assert_eq!(out, "0x6060 = 01\n0x1018 = 03\n");
    let sim = zimmer();
    a.quiet = true;
    a.ty = Some(eds2rust::ir::DataType::Integer8);
    let (out, r) = run(|o| sdo::read(|| Ok(sim.bus()), &a, o));
    r.unwrap();
    assert_eq!(out, "1\n3\n");
}

#[test]
fn sdo_write_named_value_unit_and_errors() {
    let sim = zimmer();
    let mut w = sdo::WriteArgs {
        verify: true,
        ..write_args(
            to(40, Some("zimmer_acs.yaml")),
            None,
            "ModesOfOperation",
            "cyclic synchronous position",
        )
    };
    let (out, r) = run(|o| sdo::write(|| Ok(sim.bus()), &w, o));
    r.unwrap();
    assert_eq!(
        out,
        "0x6060 Modes of operation := 8 \"cyclic synchronous position\"\n\
         0x6060 Modes of operation = 8 \"cyclic synchronous position\" (read back)\n"
    );
    // Read-only per the OD: refused before the bus.
    w.object = "Statusword".into();
    w.value = "1".into();
    let (_, r) = run(|o| sdo::write(|| Ok(LiveBus::new(Box::new(NoBus))), &w, o));
    assert!(
        matches!(&r, Err(LiveError::Usage(m)) if m.contains("read-only")),
        "{r:?}"
    );
    // A name that does not exist, with a suggestion.
    w.object = "ModesOfOperatoin".into();
    let (_, r) = run(|o| sdo::write(|| Ok(LiveBus::new(Box::new(NoBus))), &w, o));
    assert!(
        matches!(&r, Err(LiveError::Usage(m)) if m.contains("did you mean `ModesOfOperation`")),
        "{r:?}"
    );
    // Without --od the type is needed.
    w.to.od = None;
    w.object = "0x6060".into();
    let (_, r) = run(|o| sdo::write(|| Ok(LiveBus::new(Box::new(NoBus))), &w, o));
    assert!(
        matches!(&r, Err(LiveError::Usage(m)) if m.contains("--type")),
        "{r:?}"
    );
    // A value out of range.
    w.to.od = Some(eds("zimmer_acs.yaml"));
    w.object = "0x6060".into();
    w.value = "300".into();
    let (_, r) = run(|o| sdo::write(|| Ok(LiveBus::new(Box::new(NoBus))), &w, o));
    assert!(
        matches!(&r, Err(LiveError::Usage(m)) if m.contains("outside the range")),
        "{r:?}"
    );
}

#[test]
fn sdo_errors_name_node_object_and_abort_code() {
    let sim = zimmer();
    let w = write_args(
        to(40, None),
        Some(eds2rust::ir::DataType::Unsigned16),
        "0x6041",
        "1",
    );
    let (_, r) = run(|o| sdo::write(|| Ok(sim.bus()), &w, o));
    let Err(LiveError::Failed(m)) = r else {
        panic!("{r:?}")
    };
    assert_eq!(
        m,
        "node 40, 0x6041: write failed: the SDO peer aborted the transfer: 0x06010002 \
         (attempt to write a read only object)"
    );
    let sim = zimmer();
    let mut a = read_args(41, None, &["0x1000"]);
    a.to.bus = bus_args(50);
    let (_, r) = run(|o| sdo::read(|| Ok(sim.bus()), &a, o));
    assert_eq!(
        r,
        Err(LiveError::Failed(
            "node 41, 0x1000: read failed: no answer within 50 ms (is node 41 on the bus?)".into()
        ))
    );
}

/// A bus that must not be used.
struct NoBus;

impl eds2rust_runtime::transport::Bus for NoBus {
    fn send(&mut self, _: &eds2rust_runtime::Frame) -> std::io::Result<()> {
        panic!("the command used the bus")
    }
    fn recv(&mut self, _: Duration) -> std::io::Result<Option<eds2rust_runtime::Frame>> {
        panic!("the command used the bus")
    }
}

#[test]
fn nmt_and_scan() {
    let sim = Sim::start(linak_techline::simulator);
    // Heartbeats every 100 ms: the scan hears the state.
    let hb = write_args(
        to(32, None),
        Some(eds2rust::ir::DataType::Unsigned16),
        "0x1017",
        "100",
    );
    run(|o| sdo::write(|| Ok(sim.bus()), &hb, o)).1.unwrap();
    let scan_args = ScanArgs {
        bus: bus_args(500),
        listen: Duration::from_millis(300),
        probe_timeout: Duration::from_millis(100),
        no_probe: false,
    };
    let (out, r) = run(|o| nmt::scan(|| Ok(sim.bus()), &scan_args, o));
    r.unwrap();
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), 3, "{out}");
    assert!(lines[0].starts_with("node  state"), "{out}");
    assert!(lines[1].starts_with("  32  pre-operational  0x"), "{out}");
    assert_eq!(
        lines[2],
        "1 node found (1 answered SDO, 1 sent boot-up or heartbeat)"
    );
    assert_eq!(
        lines[0],
        "node  state            device type  vendor id   product code  revision    serial"
    );

    let args = NmtArgs {
        verb: NmtVerb::Start,
        bus: bus_args(500),
        node: Some(32),
        all: false,
        confirm: true,
    };
    let (out, r) = run(|o| nmt::command(|| Ok(sim.bus()), &args, o));
    r.unwrap();
    assert_eq!(
        out,
        "sent NMT start to node 32\nnode 32: operational (heartbeat)\n"
    );
    // Neither a node nor --all: nothing is sent, no broadcast by default.
    let args = NmtArgs {
        node: None,
        confirm: false,
        ..args
    };
    let (out, r) = run(|o| nmt::command(|| Ok(sim.bus()), &args, o));
    assert!(matches!(r, Err(LiveError::Usage(_))), "{r:?}");
    assert_eq!(out, "");
}

#[test]
fn od_upload_then_download_restores_a_changed_value() {
    let dir = scratch("");
    let dcf = dir.join("node40.dcf");
    let sim = zimmer();
    let up = upload_args(bus_args(500), 40, &dcf);
    let (_, r) = run(|o| backup::upload(|| Ok(sim.bus()), &up, o));
    r.unwrap();
    let text = std::fs::read_to_string(&dcf).unwrap();
    assert!(text.contains("[DeviceComissioning]\nNodeID=40\n"), "{text}");
    assert!(text.contains("ParameterValue="), "{text}");
    // The backup reads as a DCF with the node's values.
    let od = od::Od::load(&dcf).unwrap();
    let (_, e) = od.entry(0x6060, 0).unwrap();
    assert_eq!(
        e.parameter_value.as_ref().unwrap().value,
        eds2rust::ir::Value::Integer(1)
    );
    let (_, e) = od.entry(0x1800, 1).unwrap();
    assert!(
        e.parameter_value.as_ref().unwrap().plus_node_id,
        "TPDO1 COB-ID stays $NODEID+0x180"
    );

    // The plan: PDO disabled, mapping count 0, entries, count, COB-ID.
    let down = download_args(true, dcf.clone());
    let (plan, r) = run(|o| backup::download_plan(&down, o));
    r.unwrap();
    let at = |needle: &str| {
        plan.find(needle)
            .unwrap_or_else(|| panic!("{needle:?} not in the plan:\n{plan}"))
    };
    assert!(plan.starts_with("download to node 40 ("), "{plan}");
    assert!(at("disable PDO: set bit 31 of 0x1800.1") < at("write 0x1800.2"));
    assert!(
        at(
            "write 0x1A00 TPDO1 mapping parameter.Highest sub-index supported := 0 (0x00) (mapping off)"
        ) < at("write 0x1A00.1")
    );
    assert!(
        at("write 0x1A00.1")
            < at("write 0x1A00 TPDO1 mapping parameter.Highest sub-index supported := 2")
    );
    assert!(
        at("write 0x1A00 TPDO1 mapping parameter.Highest sub-index supported := 2")
            < at("write 0x1800.1")
    );
    assert!(at("write 0x1800.1") < at("write 0x6060"));

    // Change a value on the node, then download the backup.
    let w = write_args(to(40, Some("zimmer_acs.yaml")), None, "0x6060", "8");
    let (_, r) = run(|o| sdo::write(|| Ok(sim.bus()), &w, o));
    r.unwrap();
    let down = backup::DownloadArgs {
        dry_run: false,
        ..down
    };
    let (out, r) = run(|o| backup::download(|| Ok(sim.bus()), &down, o));
    r.unwrap();
    // A DCF has no named values: the YAML's semantic layer stays behind,
    // but the built-in CiA 402 meaning of 0x6060 is there again.
    assert!(
        out.contains("0x6060 Modes of operation: ok 1 \"profile position\"\n"),
        "{out}"
    );
    assert!(
        out.contains("0x1A00.1 TPDO1 mapping parameter.Mapped object 1: ok "),
        "{out}"
    );
    let summary = out.lines().last().unwrap();
    assert!(
        summary.starts_with("node 40: ") && summary.contains(" 0 differed, 0 refused"),
        "{out}"
    );
    let (out, r) = run(|o| sdo::read(|| Ok(sim.bus()), &read_args(40, None, &["0x6060"]), o));
    r.unwrap();
    assert_eq!(out, "0x6060 = 01\n");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn od_download_reports_refused_entries() {
    let dir = scratch("r");
    let dcf = dir.join("bad.dcf");
    // A DCF with a value for an object the simulated device does not have.
    let mut device = od::Od::load(&eds("zimmer_acs.yaml")).unwrap().device;
    let mut object = device.objects.get(&0x6060).unwrap().clone();
    object.index = 0x2FFF;
    object.name = "Not on the device".into();
    let entry = object.entries.get_mut(&0).unwrap();
    entry.parameter_value = Some(eds2rust::ir::Literal {
        value: eds2rust::ir::Value::Integer(3),
        plus_node_id: false,
        text: "3".into(),
    });
    device.objects.insert(0x2FFF, object);
    device.commissioning = Some(eds2rust::ir::Commissioning {
        node_id: Some(40),
        ..Default::default()
    });
    std::fs::write(&dcf, eds2rust::r#gen::to_eds(&device)).unwrap();
    let sim = zimmer();
    let down = download_args(false, dcf);
    let (out, r) = run(|o| backup::download(|| Ok(sim.bus()), &down, o));
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(
        lines.first().copied(),
        Some(
            "0x2FFF Not on the device: refused 3: 0x06020000 (object does not exist in the \
             object dictionary)"
        ),
        "{out}"
    );
    let summary = lines.last().unwrap();
    assert!(summary.contains(" 0 differed, 1 refused, "), "{out}");
    assert_eq!(
        r,
        Err(LiveError::Failed(
            "node 40: 0 entries differed, 1 were refused".into()
        ))
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn lss_fastscan_and_set_node_id() {
    let serial = 0x0012_D687;
    let identity = Identity::new(
        eds2rust_drivers::interroll_ec5000bi::VENDOR_ID,
        eds2rust_drivers::interroll_ec5000bi::PRODUCT_CODE,
        eds2rust_drivers::interroll_ec5000bi::REVISION_NUMBER,
        serial,
    );
    let config = DeviceConfig {
        node: None,
        lss: Some(identity),
        bit_rate: eds2rust_runtime::lss::BitRate::Kbit250,
    };
    let sim = Sim::start(|now| {
        interroll_ec5000bi::simulator_with(interroll_ec5000bi::Ec5000Bi::new(), config, now)
    });
    let scan = lss::ScanArgs {
        bus: bus_args(500),
        lss_timeout: Duration::from_millis(10),
        assign: None,
        store: false,
    };
    let (out, r) = run(|o| lss::scan(|| Ok(sim.bus()), &scan, o));
    r.unwrap();
    assert_eq!(
        out,
        format!(
            "vendor id   product code  revision    serial\n\
             0x{:08X}  0x{:08X}    0x{:08X}  0x0012D687\n\
             1 LSS slave without a node id\n",
            identity.vendor_id, identity.product_code, identity.revision
        )
    );
    let set = lss::SetNodeIdArgs {
        bus: bus_args(500),
        lss_timeout: Duration::from_millis(50),
        identity: Some(identity),
        fastscan: false,
        global: false,
        store: true,
        activate: true,
        node: 5,
    };
    let (out, r) = run(|o| lss::set_node_id(|| Ok(sim.bus()), &set, o));
    r.unwrap();
    assert!(out.ends_with("node id 5 configured\nstored\nsent NMT reset communication to all nodes\nnode 5: boot-up seen\n"), "{out}");
    // Node 5 answers SDO now.
    let (out, r) = run(|o| sdo::read(|| Ok(sim.bus()), &read_args(5, None, &["0x1018.4"]), o));
    r.unwrap();
    assert_eq!(out, "0x1018.4 = 87 D6 12 00\n");
    // A file into a string entry by block transfer, read back.
    let dir = scratch("f");
    let file = dir.join("catalogue.txt");
    std::fs::write(&file, "CAT-0123456789-ABCDEFGHIJ").unwrap();
    let d = sdo::DownloadFileArgs {
        to: to(5, Some("interroll_ec5000bi.yaml")),
        segmented: false,
        object: "Motor Catalogue Number".into(),
        file: file.clone(),
    };
    let (out, r) = run(|o| sdo::download_file(|| Ok(sim.bus()), &d, o));
    r.unwrap();
    assert_eq!(
        out,
        format!(
            "0x6403 Motor Catalogue Number: downloaded 25 bytes from {} (block transfer)\n",
            file.display()
        )
    );
    let a = read_args(5, Some("interroll_ec5000bi.yaml"), &["0x6403"]);
    let (out, r) = run(|o| sdo::read(|| Ok(sim.bus()), &a, o));
    r.unwrap();
    assert_eq!(
        out,
        "0x6403 Motor Catalogue Number = \"CAT-0123456789-ABCDEFGHIJ\"\n"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn od_upload_of_a_silent_node_writes_no_dcf() {
    let dir = scratch("s");
    let dcf = dir.join("node41.dcf");
    let sim = zimmer();
    let up = upload_args(bus_args(50), 41, &dcf);
    let (out, r) = run(|o| backup::upload(|| Ok(sim.bus()), &up, o));
    assert_eq!(out, "");
    let Err(LiveError::Failed(m)) = r else {
        panic!("{r:?}")
    };
    // The first entry of the table (0x1003.0) is the one that timed out.
    assert_eq!(
        m,
        "node 41, 0x1003 Pre-defined error field.Number of errors: read failed: no answer \
         within 50 ms (is node 41 on the bus?)"
    );
    assert!(!dcf.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
