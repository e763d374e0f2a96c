//! A simulated belt conveyor drive, built with eds2rust-sim's generic device
//! from nothing but this crate's own object table.
//!
//! `build.rs` generates [`conveyor`] from `od/conveyor.yaml`: one type per
//! entry (`conveyor::od::SpeedSetpoint`, ...), the bit fields of the status
//! byte and the TPDO struct `conveyor::pdo::Tpdo1Status`. [`simulator`] runs
//! that table as a CiA 301 slave (SDO server with access, type and limit
//! checks, NMT, heartbeat, TPDO1 from its mapping) and [`Belt`] adds the
//! mechanics. The tests run it on the virtual bus against the runtime's
//! master.
#![forbid(unsafe_code)]

use std::convert::Infallible;
use std::time::Duration;

use eds2rust_runtime::Instant;
use eds2rust_runtime::nmt::NmtState;
use eds2rust_runtime::od::NodeId;
use eds2rust_sim::{Behaviour, Context, Device, DeviceConfig};

/// The conveyor's typed object dictionary, generated from `od/conveyor.yaml`.
pub mod conveyor {
    include!(concat!(env!("OUT_DIR"), "/conveyor.rs"));
}

use conveyor::od;

/// The belt: while the drive is operational, the actual speed follows the
/// set-point at once and the position counts the millimetres travelled.
#[derive(Debug, Default)]
pub struct Belt {
    last_step: Option<Instant>,
    travelled_nm: u64,
}

impl Behaviour for Belt {
    type Event = Infallible;

    fn step(&mut self, ctx: &mut Context<'_, Infallible>) {
        let now = ctx.now();
        let elapsed = self
            .last_step
            .map_or(Duration::ZERO, |last| now.saturating_duration_since(last));
        self.last_step = Some(now);

        let speed = match ctx.nmt_state() {
            NmtState::Operational => ctx.get::<od::SpeedSetpoint>().map_or(0, |s| s.to_raw()),
            _ => 0,
        };
        // mm/s × µs = nm.
        let micros = u64::try_from(elapsed.as_micros()).unwrap_or(u64::MAX);
        self.travelled_nm = self
            .travelled_nm
            .saturating_add(u64::from(speed.unsigned_abs()).saturating_mul(micros));
        let position_mm = (self.travelled_nm / 1_000_000) as u32; // wraps, as documented

        ctx.set::<od::ActualSpeed>(od::ActualSpeedValue::from_raw(speed));
        ctx.set::<od::BeltPosition>(od::BeltPositionValue::from_raw(position_mm));
        ctx.set::<od::BeltStatus>(
            od::BeltStatusValue::from_raw(0)
                .with_running(speed != 0)
                .with_reverse(speed < 0),
        );
    }

    fn reset_application(&mut self, _ctx: &mut Context<'_, Infallible>) {
        *self = Belt::default();
    }
}

/// The conveyor at `node`, powered on at `now`.
pub fn simulator(node: NodeId, now: Instant) -> Device<Belt> {
    Device::new(od::OBJECTS, DeviceConfig::node(node), Belt::default(), now)
}
