//! Zimmer ACS40 / ACS60 compact axis (ball screw, CANopen): a behaviour
//! model written from the manual "Montage- und Betriebsanleitung ACS"
//! (DDOC02148 / b DE / 14.02.2025), on the generated table
//! [`eds2rust_drivers::zimmer_acs::od`].
//!
//! What it does, with the chapter each part comes from:
//! - CiA 402 state machine (15.1): the runtime's [`DeviceStateMachine`]
//!   takes the transitions; controlword 0x6040, statusword 0x6041 (bit 4
//!   "voltage enabled" = power stage on, 11.3; bit 9 reserved, so 0; bit 14
//!   "initial angle determination finished", set at the first enable after
//!   power-on — the manual names the bit but not when it rises, this is
//!   what a drive that determines the commutation angle at enable does).
//!   Fault reset (transition 15) also clears controlword bit 7 in the
//!   device, as the 15.1.1 event table says.
//! - Modes (11.1.2, 15.5): profile position (1, the default) and cyclic
//!   synchronous position (8); other values of 0x6060 are refused.
//! - Profile position (15.1.1 bits 4-6 and 8, 15.1.2.1): new set-point /
//!   set-point acknowledge / target reached, absolute or relative (to the
//!   preceding target, the CiA 402 default), change immediately or set of
//!   set-points (one buffered), halt (0x605D); a trapezoid with 0x6081,
//!   0x6083, 0x6084 in mm/s and mm/s², positions in µm. Target reached
//!   needs the position window 0x21F1 for a window time (15.1.2.1; the
//!   manual gives the time no object, it is [`POSITION_WINDOW_TIME`] here).
//! - Limits (15.5): 0x6081/0x6083/0x6084 are restricted to 0x3008..0x300A;
//!   a value 0 is error 0x7391 "profiler parameters not valid". A target
//!   outside 0x3007 is clamped and statusword bit 11 (internal limit) set:
//!   the manual does not say, this is what CiA 402 does. Enabling outside
//!   0x3007 is error 0x738C (15.4).
//! - Following error (15.5: 0x6065 window, 0x6066 timeout, 0x60F4): bit 13
//!   and error 0x7387. [`ZimmerAcs::set_blocked`] blocks the carriage.
//! - STO (16.1.3, 0x251A): [`ZimmerAcs::set_sto`] sets the two inputs; no
//!   power stage unless both are high; inputs that differ for
//!   [`STO_LATCH_TIME`] latch error 0x3282 until power-on. STO dropping in
//!   Operation enabled is error 0x3283; switching on with STO active is
//!   0x3280 (15.4).
//! - Clamping element (11.6, 0x2129): 0 = the state machine releases it in
//!   Operation enabled and Quick stop active, 1 = released, 2 = locked. A
//!   locked clamp holds the carriage, so a move ends in a following error.
//! - Errors (12, 15.4): every fault sets 0x603F, sends EMCY with the error
//!   ID (the manual has no 0x1001, so the error register byte is 0) and
//!   enters Fault; a fault reset sends EMCY 0x0000. The reaction of every
//!   modelled error is "power stage shutdown": the fault reaction ends at
//!   once.
//! - Store/restore (11.4.4, 11.5): the generic device's 0x1010 "save" /
//!   0x1011 "load" (defaults at the next power-on) match the manual.
//!
//! Values the manual leaves to the data sheet (limits, profile and
//! monitoring defaults) are assumptions, listed in `factory.rs`.

mod factory;
mod logic;

use std::time::Duration;

use eds2rust_drivers::zimmer_acs::errors::ZimmerErrors;
use eds2rust_drivers::zimmer_acs::{DEFAULT_NODE_ID, od};
use eds2rust_runtime::Instant;
use eds2rust_runtime::cia402::State;
use eds2rust_runtime::lss::BitRate;
use eds2rust_runtime::od::{Entry, NodeId};
use eds2rust_runtime::sdo::abort::AbortCode;

use crate::cia402::axis::Axis;
use crate::{Behaviour, Context, Device, DeviceConfig};
pub use factory::Variant;

/// The node id at delivery (11.2 Quickstart: 40).
pub const NODE: NodeId = match NodeId::new(DEFAULT_NODE_ID) {
    Some(node) => node,
    None => panic!("the generated default node id is 1..=127"),
};

/// The bit rate at delivery (11.2 Quickstart: 500 kbit/s).
pub const BIT_RATE: BitRate = BitRate::Kbit500;

/// How long the STO inputs may differ before the fault latches (16.1.3:
/// "> 1.4 s ~ 3.4 s"; the simulator takes the shortest).
pub const STO_LATCH_TIME: Duration = Duration::from_millis(1400);

/// How long the position must stay in the window 0x21F1 before target
/// reached (the manual's OBJ_POSITION_WINDOW_TIME has no index; assumed).
pub const POSITION_WINDOW_TIME: Duration = Duration::from_millis(10);

/// What the simulated axis reports to the application.
#[derive(Debug, Clone, PartialEq)]
pub enum ZimmerAcsEvent {
    /// The CiA 402 state machine took transition `transition`.
    StateChanged {
        /// The transition number (15.1.1).
        transition: u8,
        /// The state left (`None` at power-on).
        from: Option<State>,
        /// The state entered.
        to: State,
    },
    /// A new set-point was taken (profile position).
    SetPointAccepted {
        /// The absolute target it gives (µm, after the limits).
        target_um: i32,
        /// Controlword bit 6.
        relative: bool,
        /// Controlword bit 5.
        immediate: bool,
    },
    /// A target outside 0x3007 was clamped to the limit.
    TargetLimited {
        /// The target asked for (µm).
        requested_um: i64,
        /// The target used (µm).
        limited_um: i32,
    },
    /// The carriage set off towards a target.
    MotionStarted {
        /// Where it starts (µm).
        from_um: i32,
        /// Where it goes (µm).
        to_um: i32,
    },
    /// Target reached (statusword bit 10) after a move.
    TargetReached {
        /// The actual position (µm).
        position_um: i32,
    },
    /// An error of chapter 15.4 occurred: Fault, 0x603F and EMCY.
    Fault(ZimmerErrors),
    /// The STO inputs changed (true = 24 V).
    Sto {
        /// STO1.
        sto1: bool,
        /// STO2.
        sto2: bool,
    },
    /// Differing STO inputs latched the STO fault until power-on.
    StoLatched,
    /// The clamping element opened (`true`) or closed.
    Clamp {
        /// Whether it is released.
        released: bool,
    },
}

/// The simulated ACS axis (see the module documentation).
#[derive(Debug, Clone)]
pub struct ZimmerAcs {
    variant: Variant,
    /// The CiA 402 axis (positions in µm).
    axis: Axis,
    blocked: bool,
    angle_determined: bool,
    clamp_released: bool,
    sto1: bool,
    sto2: bool,
    sto_differs_since: Option<Instant>,
    sto_latched: bool,
}

impl Default for ZimmerAcs {
    fn default() -> Self {
        ZimmerAcs::new()
    }
}

impl ZimmerAcs {
    /// An ACS40 at position 0, STO inputs high (torque possible), real time.
    pub fn new() -> ZimmerAcs {
        ZimmerAcs {
            variant: Variant::Acs40,
            axis: Axis::new(),
            blocked: false,
            angle_determined: false,
            clamp_released: false,
            sto1: true,
            sto2: true,
            sto_differs_since: None,
            sto_latched: false,
        }
    }

    /// This model with the mechanics `factor` times faster than real time
    /// (a factor that is not a positive number leaves it unchanged).
    pub fn with_time_scale(mut self, factor: f64) -> ZimmerAcs {
        self.axis.set_time_scale(factor);
        self
    }

    /// This model as `variant` (stroke and control parameters).
    pub fn with_variant(mut self, variant: Variant) -> ZimmerAcs {
        self.variant = variant;
        self
    }

    /// This model with the carriage at `position_um` (µm) at power-on.
    pub fn with_position_um(mut self, position_um: i32) -> ZimmerAcs {
        self.axis.place(f64::from(position_um));
        self
    }

    /// This model with the STO inputs at power-on (true = 24 V).
    pub fn with_sto_inputs(mut self, sto1: bool, sto2: bool) -> ZimmerAcs {
        self.sto1 = sto1;
        self.sto2 = sto2;
        self
    }

    /// The mechanics' speed-up over real time.
    pub fn time_scale(&self) -> f64 {
        self.axis.time_scale
    }

    /// The size of the axis.
    pub fn variant(&self) -> Variant {
        self.variant
    }

    /// The CiA 402 state (`None` before power-on).
    pub fn state(&self) -> Option<State> {
        self.axis.state()
    }

    /// The actual carriage position (µm).
    pub fn position_um(&self) -> f64 {
        self.axis.actual
    }

    /// The demand position of the trajectory generator (µm).
    pub fn demand_um(&self) -> f64 {
        self.axis.profiler.position
    }

    /// Whether the clamping element is released.
    pub fn clamp_released(&self) -> bool {
        self.clamp_released
    }

    /// The STO inputs (STO1, STO2; true = 24 V).
    pub fn sto_inputs(&self) -> (bool, bool) {
        (self.sto1, self.sto2)
    }

    /// Blocks the carriage (a crash, a jammed guide): it no longer follows
    /// the demand, so a move ends in a following error (0x7387).
    pub fn set_blocked(&mut self, blocked: bool) {
        self.blocked = blocked;
    }

    /// Sets the STO inputs (16.1.3; true = 24 V). STO going active in
    /// Operation enabled is error 0x3283.
    pub fn set_sto(&mut self, ctx: &mut Context<'_, ZimmerAcsEvent>, sto1: bool, sto2: bool) {
        self.begin(ctx);
        let was_ok = self.sto_ok();
        self.sto1 = sto1;
        self.sto2 = sto2;
        self.sto_differs_since = match (sto1 != sto2, self.sto_differs_since) {
            (true, since) => Some(since.unwrap_or(ctx.now())),
            (false, _) => None,
        };
        ctx.emit(ZimmerAcsEvent::Sto { sto1, sto2 });
        if was_ok && !self.sto_ok() && self.state() == Some(State::OperationEnabled) {
            self.fault(ctx, ZimmerErrors::StoActiveInOperationEnabled);
        }
        self.finish(ctx);
    }

    /// Raises an error of chapter 15.4 from outside (over-temperature,
    /// under-voltage, ...): Fault, 0x603F, EMCY.
    pub fn inject_fault(&mut self, ctx: &mut Context<'_, ZimmerAcsEvent>, error: ZimmerErrors) {
        self.begin(ctx);
        self.fault(ctx, error);
        self.finish(ctx);
    }
}

/// Whether `value` is one of the modes of 11.1.2.
fn supported_mode(value: i8) -> bool {
    value == od::ModesOfOperationValue::PROFILE_POSITION.0
        || value == od::ModesOfOperationValue::CYCLIC_SYNCHRONOUS_POSITION.0
}

impl Behaviour for ZimmerAcs {
    type Event = ZimmerAcsEvent;

    fn check_write(
        &mut self,
        ctx: &mut Context<'_, ZimmerAcsEvent>,
        index: u16,
        sub: u8,
        data: &[u8],
    ) -> Result<(), AbortCode> {
        let byte = data.first().copied().unwrap_or(0);
        let word = |d: &[u8]| match d {
            [lo, hi] => i32::from(i16::from_le_bytes([*lo, *hi])),
            _ => -1,
        };
        match (index, sub) {
            (od::ModesOfOperation::INDEX, 0) if !supported_mode(byte as i8) => {
                Err(AbortCode::InvalidValue)
            }
            // 15.5: 0, 1, 2, 5, 6.
            (od::QuickStopOptionCode::INDEX, 0) if !matches!(word(data), 0 | 1 | 2 | 5 | 6) => {
                Err(AbortCode::InvalidValue)
            }
            // 15.5: 1, 2 (0 reserved); not while the power stage is on.
            (od::HaltOptionCode::INDEX, 0) => {
                self.begin(ctx);
                if self.power_stage_on() {
                    Err(AbortCode::CannotTransferDeviceState)
                } else if !matches!(word(data), 1 | 2) {
                    Err(AbortCode::InvalidValue)
                } else {
                    Ok(())
                }
            }
            // 11.6: 0, 1, 2.
            (od::ClampingElementOverride::INDEX, 0) if !matches!(word(data), 0..=2) => {
                Err(AbortCode::InvalidValue)
            }
            _ => Ok(()),
        }
    }

    fn written(&mut self, ctx: &mut Context<'_, ZimmerAcsEvent>, index: u16, sub: u8) {
        self.begin(ctx);
        match (index, sub) {
            (od::Controlword::INDEX, 0) => self.apply_controlword(ctx),
            (od::ModesOfOperation::INDEX, 0) => self.apply_mode(ctx),
            _ => {}
        }
        self.finish(ctx);
    }

    fn step(&mut self, ctx: &mut Context<'_, ZimmerAcsEvent>) {
        self.begin(ctx);
        self.monitor(ctx);
        self.finish(ctx);
    }

    fn reset_application(&mut self, ctx: &mut Context<'_, ZimmerAcsEvent>) {
        self.power_on(ctx);
    }
}

/// The device configuration at delivery: node 40, 500 kbit/s (11.2). The
/// manual describes no LSS.
pub fn default_config() -> DeviceConfig {
    DeviceConfig {
        node: Some(NODE),
        lss: None,
        bit_rate: BIT_RATE,
    }
}

/// A simulated ACS40 as delivered, powered on at `now`.
pub fn simulator(now: Instant) -> Device<ZimmerAcs> {
    simulator_with(ZimmerAcs::new(), default_config(), now)
}

/// A simulated axis with `model` and `config`, powered on at `now`.
pub fn simulator_with(model: ZimmerAcs, config: DeviceConfig, now: Instant) -> Device<ZimmerAcs> {
    let mut device = Device::new(od::OBJECTS, config, model, now);
    device.with_model(now, |model, ctx| model.power_on(ctx));
    device
}
