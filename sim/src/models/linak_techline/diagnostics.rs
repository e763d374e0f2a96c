//! Errors and statistics: the LINAK error code of the feedback (0x2001
//! sub 4, p. 33 and p. 47-49), the EMCY that goes with it (p. 52), the
//! error register 0x1001 (CiA 301) and the counters of 0x4000 (p. 40-46).

use eds2rust_drivers::linak_techline::errors::{
    Emcy, EmcyCode, LastStopReasons, LastStopReasonsCode, LinakErrors, LinakErrorsCode,
};
use eds2rust_drivers::linak_techline::od::{self, configuration as cfg};
use eds2rust_runtime::od::{Entry, Scalar};

use crate::Context;

/// The errors the model raises, highest priority first. The manual says
/// only that the feedback shows "the currently active error with the
/// highest priority" (p. 33); this order (supply, mechanics, communication,
/// power-up lock) is the model's.
const PRIORITY: [LinakErrors; 4] = [
    LinakErrors::Undervoltage,
    LinakErrors::PositionNotChanging,
    LinakErrors::CommunicationSynchronisation,
    LinakErrors::PowerUpLock,
];

/// Error register 0x1001 bits (CiA 301 7.5.2.2).
const REG_GENERIC: u8 = 0x01;
const REG_VOLTAGE: u8 = 0x04;
const REG_COMMUNICATION: u8 = 0x10;
const REG_MANUFACTURER: u8 = 0x80;

/// The EMCY (p. 52) and error register bits of a LINAK error; `None` for
/// the power-up lock, which the start-up trace (p. 28) shows without EMCY.
pub(super) fn emcy_of(error: LinakErrors) -> Option<(Emcy, u8)> {
    match error {
        LinakErrors::Undervoltage => Some((Emcy::Undervoltage, REG_GENERIC | REG_VOLTAGE)),
        LinakErrors::PositionNotChanging => {
            Some((Emcy::PositionNotChanging, REG_GENERIC | REG_MANUFACTURER))
        }
        LinakErrors::CommunicationSynchronisation => {
            Some((Emcy::HeartbeatError, REG_GENERIC | REG_COMMUNICATION))
        }
        _ => None,
    }
}

/// The active errors.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub(super) struct Errors {
    active: Vec<LinakErrors>,
}

impl Errors {
    /// Whether `error` is active.
    pub(super) fn has(&self, error: LinakErrors) -> bool {
        self.active.contains(&error)
    }

    /// The error the feedback shows (0 when none).
    pub(super) fn reported(&self) -> LinakErrors {
        PRIORITY
            .into_iter()
            .find(|e| self.has(*e))
            .unwrap_or(LinakErrors::NoError)
    }

    /// Forgets every error (power-on), without EMCY.
    pub(super) fn reset(&mut self) {
        self.active.clear();
    }

    fn register(&self) -> u8 {
        self.active
            .iter()
            .filter_map(|e| emcy_of(*e))
            .fold(0, |r, (_, bits)| r | bits)
    }

    /// Raises `error`; a new error with an EMCY code sets the error register
    /// and sends the EMCY (manufacturer bytes 0: the manual defines none).
    /// Returns whether it is new.
    pub(super) fn raise<E>(&mut self, ctx: &mut Context<'_, E>, error: LinakErrors) -> bool {
        if self.has(error) {
            return false;
        }
        self.active.push(error);
        if let Some((emcy, _)) = emcy_of(error) {
            ctx.set::<od::ErrorRegister>(od::ErrorRegisterValue::from_raw(self.register()));
            ctx.emcy(EmcyCode::from_kind(emcy).to_raw(), [0; 5]);
        }
        true
    }

    /// Clears `error`; when the last error with an EMCY goes, the error
    /// register returns to 0 and EMCY 0x0000 "error reset" is sent
    /// (CiA 301 7.2.7.1). Returns whether it was active.
    pub(super) fn clear<E>(&mut self, ctx: &mut Context<'_, E>, error: LinakErrors) -> bool {
        let Some(i) = self.active.iter().position(|e| *e == error) else {
            return false;
        };
        self.active.remove(i);
        if emcy_of(error).is_some() {
            let register = self.register();
            ctx.set::<od::ErrorRegister>(od::ErrorRegisterValue::from_raw(register));
            if register == 0 {
                ctx.emcy(EmcyCode::from_kind(Emcy::NoError).to_raw(), [0; 5]);
                ctx.clear_error_field();
            }
        }
        true
    }

    /// The feedback's error code.
    pub(super) fn code(&self) -> LinakErrorsCode {
        LinakErrorsCode::from_kind(self.reported())
    }
}

/// Adds one to a counter entry of 0x4000, saturating at its type's maximum.
pub(super) fn bump<T, E>(ctx: &mut Context<'_, E>)
where
    T: Entry,
    T::Value: Scalar,
{
    let bits = T::DATA_TYPE.size().unwrap_or(4).min(8) * 8;
    let max = if bits >= 64 {
        u64::MAX
    } else {
        (1u64 << bits) - 1
    };
    let now = ctx.get::<T>().map_or(0, Scalar::to_raw);
    ctx.set::<T>(T::Value::from_raw(now.saturating_add(1).min(max)));
}

/// Raises a counter entry of 0x4000 to `value` if it is higher (maximum
/// measured values).
pub(super) fn raise_to<T, E>(ctx: &mut Context<'_, E>, value: u64)
where
    T: Entry,
    T::Value: Scalar,
{
    if ctx.get::<T>().map_or(0, Scalar::to_raw) < value {
        ctx.set::<T>(T::Value::from_raw(value));
    }
}

/// The subindices of the five "reason for last stop" groups (ID 0 newest;
/// reason, count, operating time; p. 43).
const LAST_STOPS: [(u8, u8, u8); 5] = [
    (
        cfg::LastStop0Reason::SUBINDEX,
        cfg::LastStop0Count::SUBINDEX,
        cfg::LastStop0OperatingTime::SUBINDEX,
    ),
    (
        cfg::LastStop1Reason::SUBINDEX,
        cfg::LastStop1Count::SUBINDEX,
        cfg::LastStop1OperatingTime::SUBINDEX,
    ),
    (
        cfg::LastStop2Reason::SUBINDEX,
        cfg::LastStop2Count::SUBINDEX,
        cfg::LastStop2OperatingTime::SUBINDEX,
    ),
    (
        cfg::LastStop3Reason::SUBINDEX,
        cfg::LastStop3Count::SUBINDEX,
        cfg::LastStop3OperatingTime::SUBINDEX,
    ),
    (
        cfg::LastStop4Reason::SUBINDEX,
        cfg::LastStop4Count::SUBINDEX,
        cfg::LastStop4OperatingTime::SUBINDEX,
    ),
];

/// Records a stop for `reason` (table p. 46) at `operating_s` seconds of
/// running time: the same reason as ID 0 counts up ("number of stops in a
/// row"), another one pushes the older ones down to ID 4.
pub(super) fn record_stop<E>(ctx: &mut Context<'_, E>, reason: LastStopReasons, operating_s: u32) {
    let index = cfg::INDEX;
    let code = LastStopReasonsCode::from_kind(reason).to_raw();
    let table = ctx.table_mut();
    let [(reason0, count0, time0), ..] = LAST_STOPS;
    let same = table.get_uint(index, reason0) == Some(u64::from(code));
    if same {
        let count = table.get_uint(index, count0).unwrap_or(0).min(254) as u8;
        let _ = table.set_raw(index, count0, &[count + 1]);
    } else {
        for pair in LAST_STOPS.windows(2).rev() {
            let [from, to] = pair else { continue };
            for (src, dst) in [(from.0, to.0), (from.1, to.1), (from.2, to.2)] {
                if let Some(bytes) = table.get(index, src).map(<[u8]>::to_vec) {
                    let _ = table.set_raw(index, dst, &bytes);
                }
            }
        }
        let _ = table.set_raw(index, reason0, &code.to_le_bytes());
        let _ = table.set_raw(index, count0, &[1]);
    }
    let _ = table.set_raw(index, time0, &operating_s.to_le_bytes());
}
