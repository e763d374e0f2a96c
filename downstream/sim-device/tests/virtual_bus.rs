//! The simulated conveyor on the in-process virtual bus, driven by the
//! runtime's blocking master through the generated objects.

use std::error::Error;
use std::ops::ControlFlow;
use std::time::{Duration, Instant as WallClock};

use eds2rust_runtime::blocking::{self, Master};
use eds2rust_runtime::master::{self, MasterEvent};
use eds2rust_runtime::nmt::{NmtCommand, NmtEvent};
use eds2rust_runtime::od::{NodeId, Scaled};
use eds2rust_runtime::pdo::PdoEvent;
use eds2rust_runtime::sdo::SdoError;
use eds2rust_runtime::sdo::abort::AbortCode;
use eds2rust_sim::harness::{Args, Harness, MasterPort};
use sim_device::conveyor::{self, od, pdo::Tpdo1Status};

type Result<T = ()> = std::result::Result<T, Box<dyn Error>>;

/// How long any answer may take.
const TIMEOUT: Duration = Duration::from_secs(2);

fn node(id: u8) -> NodeId {
    NodeId::new(id).expect("a node id in 1..=127")
}

/// The abort code an SDO transfer failed with.
fn abort_code<T>(result: std::result::Result<T, blocking::Error>) -> Option<AbortCode> {
    match result {
        Err(blocking::Error::Sdo {
            error: SdoError::RemoteAbort(code),
            ..
        }) => Some(code),
        _ => None,
    }
}

/// The next TPDO1 of `node`, decoded.
fn next_status(m: &mut Master<MasterPort>, node: NodeId) -> Result<Tpdo1Status> {
    let tpdo1 = Tpdo1Status::can_id(node);
    let data = m.run_until(WallClock::now() + TIMEOUT, |event| match event {
        MasterEvent::Pdo(PdoEvent::Received {
            can_id, data, len, ..
        }) if *can_id == tpdo1 => ControlFlow::Break(data[..*len].to_vec()),
        _ => ControlFlow::Continue(()),
    })?;
    Ok(Tpdo1Status::decode(&data)?)
}

#[test]
fn boots_answers_sdo_and_sends_its_tpdo() -> Result {
    let drive = node(conveyor::DEFAULT_NODE_ID);
    let mut harness = Harness::start(&Args::default(), |now| sim_device::simulator(drive, now))?;
    let mut core = master::Master::new(node(1), None);
    core.pdo_rx.watch_pdo::<Tpdo1Status>(drive)?;
    let mut m = Master::with_clock(harness.take_port()?, core, harness.clock());
    m.start()?;

    // Boot-up (sent by the harness before the master started).
    m.run_until(WallClock::now() + TIMEOUT, |event| match event {
        MasterEvent::Nmt(NmtEvent::BootUp(n)) if *n == drive => ControlFlow::Break(()),
        _ => ControlFlow::Continue(()),
    })?;

    // SDO reads and writes with the generated entry types.
    assert_eq!(
        m.read::<od::identity::VendorId>(drive)?,
        conveyor::VENDOR_ID
    );
    assert_eq!(
        m.read::<od::SpeedSetpoint>(drive)?,
        od::SpeedSetpoint::DEFAULT
    );
    let speed = od::SpeedSetpointValue::from_raw(500); // mm/s
    m.write::<od::SpeedSetpoint>(drive, speed)?;
    assert_eq!(m.read::<od::SpeedSetpoint>(drive)?, speed);
    // The table's limits (-2000..=2000 mm/s) are enforced.
    let too_fast = m.write::<od::SpeedSetpoint>(drive, od::SpeedSetpointValue::from_raw(2500));
    assert_eq!(abort_code(too_fast), Some(AbortCode::ValueTooHigh));

    // `m.write::<od::ActualSpeed>(..)` does not compile (the entry is
    // read-only); with raw bytes the device refuses it.
    let raw = m.download(drive, 0x2001, 0, &100i16.to_le_bytes());
    assert_eq!(abort_code(raw), Some(AbortCode::WriteReadOnly));

    // Operational: the belt runs and TPDO1 reports it.
    m.nmt(NmtCommand::Start, drive)?;
    let deadline = WallClock::now() + TIMEOUT;
    let status = loop {
        let status = next_status(&mut m, drive)?;
        if status.belt_position.to_raw() > 0 || WallClock::now() > deadline {
            break status;
        }
    };
    assert_eq!(status.actual_speed.to_raw(), 500);
    assert!(status.belt_position.value() > 0.0, "{status:?}");
    assert!(
        status.belt_status.running() && !status.belt_status.reverse(),
        "{status:?}"
    );

    harness.stop()?;
    Ok(())
}
