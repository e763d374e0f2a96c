//! What makes a simulated device more than an object store: a
//! [`Behaviour`] reacts to writes, to NMT and heartbeat changes and to
//! SYNC, and moves its simulated mechanics on every step, through a
//! [`Context`] onto the device's object table.

use std::collections::VecDeque;
use std::time::Duration;

use eds2rust_runtime::Instant;
use eds2rust_runtime::nmt::NmtState;
use eds2rust_runtime::od::{Entry, NodeId, Scalar};
use eds2rust_runtime::sdo::abort::AbortCode;

use crate::store::{ObjectTable, SetError};

/// The device-specific part of a simulator. Every method has a default
/// that does nothing, so a plain object store is `()`.
pub trait Behaviour {
    /// What the model reports to the application (state changes, motion
    /// milestones), besides the generic [`crate::SimEvent`]s.
    type Event: std::fmt::Debug;

    /// A write from the bus (SDO download or RPDO) to (index, sub) passed
    /// the table's checks (exists, writable, length, limits); the model may
    /// still refuse it with an abort code, for example in the wrong device
    /// state. RPDO writes that fail are dropped.
    fn check_write(
        &mut self,
        ctx: &mut Context<'_, Self::Event>,
        index: u16,
        sub: u8,
        data: &[u8],
    ) -> Result<(), AbortCode> {
        let _ = (ctx, index, sub, data);
        Ok(())
    }

    /// A write from the bus to (index, sub) was stored.
    fn written(&mut self, ctx: &mut Context<'_, Self::Event>, index: u16, sub: u8) {
        let _ = (ctx, index, sub);
    }

    /// Moves the model on to `ctx.now()`; called every [`Behaviour::period`]
    /// from boot-up on, in every NMT state.
    fn step(&mut self, ctx: &mut Context<'_, Self::Event>) {
        let _ = ctx;
    }

    /// How often [`Behaviour::step`] runs.
    fn period(&self) -> Duration {
        Duration::from_millis(10)
    }

    /// The device's NMT state changed (`from` is `BootUp` at power-on and
    /// after a reset).
    fn nmt_changed(&mut self, ctx: &mut Context<'_, Self::Event>, from: NmtState, to: NmtState) {
        let _ = (ctx, from, to);
    }

    /// A heartbeat the device consumes (0x1016) was missed.
    fn heartbeat_lost(&mut self, ctx: &mut Context<'_, Self::Event>, node: NodeId) {
        let _ = (ctx, node);
    }

    /// A heartbeat the device consumes came back after a loss.
    fn heartbeat_resumed(&mut self, ctx: &mut Context<'_, Self::Event>, node: NodeId) {
        let _ = (ctx, node);
    }

    /// A SYNC arrived (after the synchronous RPDOs were applied).
    fn sync(&mut self, ctx: &mut Context<'_, Self::Event>) {
        let _ = ctx;
    }

    /// NMT reset node: the table is back at its stored values; the model
    /// starts again as at power-on.
    fn reset_application(&mut self, ctx: &mut Context<'_, Self::Event>) {
        let _ = ctx;
    }
}

impl Behaviour for () {
    type Event = std::convert::Infallible;
}

/// What a model asked the device to do, collected while it ran.
#[derive(Debug)]
pub(crate) struct Effects<E> {
    pub(crate) emcy: VecDeque<[u8; 8]>,
    pub(crate) events: VecDeque<E>,
    pub(crate) errors: VecDeque<SetError>,
    pub(crate) tpdo_requests: Vec<u16>,
}

impl<E> Default for Effects<E> {
    fn default() -> Self {
        Effects {
            emcy: VecDeque::new(),
            events: VecDeque::new(),
            errors: VecDeque::new(),
            tpdo_requests: Vec::new(),
        }
    }
}

/// A model's view of its device while one of its methods runs.
#[derive(Debug)]
pub struct Context<'a, E> {
    pub(crate) now: Instant,
    pub(crate) node: Option<NodeId>,
    pub(crate) nmt: NmtState,
    pub(crate) table: &'a mut ObjectTable,
    pub(crate) effects: &'a mut Effects<E>,
}

/// Index of the error register (CiA 301).
const ERROR_REGISTER: u16 = 0x1001;
/// Index of the pre-defined error field (CiA 301).
const ERROR_FIELD: u16 = 0x1003;

impl<E> Context<'_, E> {
    /// The simulated time.
    pub fn now(&self) -> Instant {
        self.now
    }

    /// The device's node id (`None` while unconfigured, waiting for LSS).
    pub fn node(&self) -> Option<NodeId> {
        self.node
    }

    /// The device's NMT state.
    pub fn nmt_state(&self) -> NmtState {
        self.nmt
    }

    /// The object table.
    pub fn table(&self) -> &ObjectTable {
        self.table
    }

    /// The object table, for raw device-side writes.
    pub fn table_mut(&mut self) -> &mut ObjectTable {
        self.table
    }

    /// The value of a generated entry (`None` if the table lacks it).
    pub fn get<T>(&self) -> Option<T::Value>
    where
        T: Entry,
        T::Value: Scalar,
    {
        self.table.value::<T>()
    }

    /// Stores the value of a generated entry, whatever its access right;
    /// returns whether it changed. A write that cannot take (the entry is
    /// not in this table) is reported as [`crate::SimEvent::ModelError`].
    pub fn set<T>(&mut self, value: T::Value) -> bool
    where
        T: Entry,
        T::Value: Scalar,
    {
        match self.table.set::<T>(value) {
            Ok(changed) => changed,
            Err(e) => {
                self.effects.errors.push_back(e);
                false
            }
        }
    }

    /// Reports `event` to the application.
    pub fn emit(&mut self, event: E) {
        self.effects.events.push_back(event);
    }

    /// Sends an EMCY frame with `code` and five bytes of manufacturer data.
    /// The error register byte is the current value of 0x1001 (when the
    /// device has one); a code other than 0 is also pushed onto the
    /// pre-defined error field 0x1003 (when the device has one), newest at
    /// sub 1. The error register itself is the model's to set, before the
    /// call.
    pub fn emcy(&mut self, code: u16, data: [u8; 5]) {
        let register = self
            .table
            .get(ERROR_REGISTER, 0)
            .and_then(|v| v.first().copied())
            .unwrap_or(0);
        let mut frame = [0u8; 8];
        frame[..2].copy_from_slice(&code.to_le_bytes());
        frame[2] = register;
        frame[3..].copy_from_slice(&data);
        self.effects.emcy.push_back(frame);
        if code != 0 {
            self.push_error_field(u32::from(code));
        }
    }

    /// Clears the pre-defined error field (count 0), as an EMCY "error
    /// reset" (code 0) usually goes with.
    pub fn clear_error_field(&mut self) {
        if self.table.has_index(ERROR_FIELD) {
            let _ = self.table.set_raw(ERROR_FIELD, 0, &[0]);
        }
    }

    /// Asks for TPDO `number` (1-based) to be sent now, whatever its
    /// transmission type (it must be valid and the device operational).
    pub fn send_tpdo(&mut self, number: u16) {
        self.effects.tpdo_requests.push(number);
    }

    fn push_error_field(&mut self, code: u32) {
        if !self.table.has_index(ERROR_FIELD) {
            return;
        }
        let capacity = (1..=254u8)
            .take_while(|sub| self.table.info(ERROR_FIELD, *sub).is_some())
            .count() as u8;
        if capacity == 0 {
            return;
        }
        for sub in (2..=capacity).rev() {
            if let Some(older) = self.table.get(ERROR_FIELD, sub - 1).map(<[u8]>::to_vec) {
                let _ = self.table.set_raw(ERROR_FIELD, sub, &older);
            }
        }
        let _ = self.table.set_raw(ERROR_FIELD, 1, &code.to_le_bytes());
        let count = self.table.get_uint(ERROR_FIELD, 0).unwrap_or(0) as u8;
        let _ = self
            .table
            .set_raw(ERROR_FIELD, 0, &[count.saturating_add(1).min(capacity)]);
    }
}
