//! The boot of one slave as a CiA 302-2 CANopen manager does it, sans-IO
//! (feature `alloc`): [`SlaveBoot`] says what to do next ([`Request`]: an
//! NMT command, an SDO read or write, a wait for the boot-up message or a
//! heartbeat) and is told what came of it. A master runs one per slave, all
//! at once, over its own SDO clients and NMT master; each step is a
//! [`BootEvent`], and a failure is a [`BootError`] with the CiA 302-2 boot
//! status ([`BootStatus`], A–O) and a sentence naming the node, the object
//! and the expected and found values.
//!
//! The steps, in order: reset the node (communication or whole node) and
//! wait for its boot-up message, or wait for it without a reset; read and
//! check the device type (0x1000) and the identity (0x1018 sub 1–4; an
//! expected 0 is not checked; 0x1000 is always read, as its answer tells
//! that the node is there: a timeout is status B, a refusal is an answer); check the software version (0x1F56 sub 1)
//! where one is expected; read the configuration date and time (0x1020
//! sub 1 and 2) and skip the configuration when they match, else write
//! every configuration entry in order; wait for the first heartbeat where
//! the master consumes one; start the node unless the master starts all
//! nodes at the end.

mod network;
mod plan;
mod report;
mod status;

use alloc::vec::Vec;
use core::fmt;

pub use network::{Action, NetworkBoot};
pub use plan::{
    ConfigWrite, MasterPlan, NetworkPlan, PdoLink, SlaveConfig, SlavePlan, Supervision,
};
pub use report::{Configuration, NetworkEvent, NetworkReport, SlaveState, SlaveStatus, ends_boot};
pub use status::BootStatus;

use crate::nmt::{NmtCommand, NmtState};
use crate::od::NodeId;
use crate::sdo::abort::AbortCode;

/// What the master is to do for the boot now.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Request {
    /// Send this NMT command to the node.
    Nmt(NmtCommand),
    /// Wait for the node's boot-up message ([`SlaveBoot::boot_up`]), or
    /// [`SlaveBoot::timed_out`].
    AwaitBootUp,
    /// Read `index`/`sub` by SDO, then [`SlaveBoot::read_done`].
    Read { index: u16, sub_index: u8 },
    /// Write by SDO, then [`SlaveBoot::write_done`].
    Write(ConfigWrite),
    /// Wait for the node's heartbeat ([`SlaveBoot::heartbeat`]), or
    /// [`SlaveBoot::timed_out`].
    AwaitHeartbeat,
}

/// One step done, for the master's events.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum BootEvent {
    /// The node sent its boot-up message.
    BootedUp,
    /// The identity matched (or was not checked).
    IdentityChecked,
    /// The configuration was current (0x1020 matched): nothing written.
    ConfigurationCurrent,
    /// The configuration was written (`entries` writes).
    Configured { entries: usize },
    /// The node's heartbeat came.
    HeartbeatStarted,
    /// The node was operational before the boot (status L: not an error).
    WasOperational,
    /// The node is booted (and started, when the plan says so).
    Booted,
}

/// Why a boot stopped.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BootError {
    pub node: NodeId,
    pub status: BootStatus,
    /// The object concerned (index, sub-index), where there is one.
    pub object: Option<(u16, u8)>,
    pub expected: Option<u32>,
    pub found: Option<u32>,
    /// The SDO abort that ended it, where one did.
    pub abort: Option<AbortCode>,
}

impl fmt::Display for BootError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "node {}: boot error {}", self.node, self.status)?;
        if let Some((index, sub)) = self.object {
            write!(f, " (0x{index:04X} sub {sub}")?;
            if let Some(expected) = self.expected {
                write!(f, ": expected 0x{expected:08X}")?;
            }
            match (self.found, self.abort) {
                (Some(found), _) => write!(f, ", found 0x{found:08X}")?,
                (None, Some(abort)) => {
                    // The configuration writes; every other step reads.
                    let transfer = match self.status {
                        BootStatus::ConfigurationFailed => "write",
                        _ => "read",
                    };
                    write!(f, ", the {transfer} was aborted: {abort}")?
                }
                (None, None) => {}
            }
            write!(f, ")")?;
        } else if let Some(abort) = self.abort {
            write!(f, " ({abort})")?;
        }
        Ok(())
    }
}

/// Where the boot of one slave stands.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Stage {
    Reset,
    AwaitBootUp,
    Identity(usize),
    Software,
    ConfigDate,
    ConfigTime(u32),
    Configure(usize),
    Heartbeat,
    Start,
    Done,
    Failed,
}

/// The identity reads: object, sub-index, the status of a mismatch.
const IDENTITY: [(u16, u8, BootStatus); 5] = [
    (0x1000, 0, BootStatus::DeviceType),
    (0x1018, 1, BootStatus::VendorId),
    (0x1018, 2, BootStatus::ProductCode),
    (0x1018, 3, BootStatus::RevisionNumber),
    (0x1018, 4, BootStatus::SerialNumber),
];

/// The boot of one slave (see the module documentation).
#[derive(Debug, Clone)]
pub struct SlaveBoot {
    plan: SlavePlan,
    stage: Stage,
    /// The request handed out and not yet answered.
    pending: bool,
}

impl SlaveBoot {
    pub fn new(plan: SlavePlan) -> SlaveBoot {
        let stage = if plan.reset.is_some() {
            Stage::Reset
        } else {
            Stage::AwaitBootUp
        };
        SlaveBoot {
            plan,
            stage,
            pending: false,
        }
    }

    pub fn node(&self) -> NodeId {
        self.plan.node
    }

    /// The plan it boots by.
    pub fn plan(&self) -> &SlavePlan {
        &self.plan
    }

    /// Whether it waits for the node's boot-up message.
    pub fn awaits_boot_up(&self) -> bool {
        self.stage == Stage::AwaitBootUp
    }

    /// Whether it waits for the node's first heartbeat.
    pub fn awaits_heartbeat(&self) -> bool {
        self.stage == Stage::Heartbeat
    }

    /// Whether the boot is over (booted or failed).
    pub fn is_finished(&self) -> bool {
        matches!(self.stage, Stage::Done | Stage::Failed)
    }

    /// The request to carry out now, once: `None` while one is pending or
    /// the boot is over.
    pub fn poll_request(&mut self) -> Option<Request> {
        if self.pending {
            return None;
        }
        let request = match &self.stage {
            Stage::Reset => {
                self.stage = Stage::AwaitBootUp;
                return self.plan.reset.map(Request::Nmt);
            }
            Stage::AwaitBootUp => Request::AwaitBootUp,
            Stage::Identity(i) => {
                let (index, sub_index, _) = IDENTITY[*i];
                Request::Read { index, sub_index }
            }
            Stage::Software => Request::Read {
                index: 0x1F56,
                sub_index: 1,
            },
            Stage::ConfigDate => Request::Read {
                index: 0x1020,
                sub_index: 1,
            },
            Stage::ConfigTime(_) => Request::Read {
                index: 0x1020,
                sub_index: 2,
            },
            Stage::Configure(i) => Request::Write(self.plan.configuration[*i].clone()),
            Stage::Heartbeat => Request::AwaitHeartbeat,
            Stage::Start => {
                self.stage = Stage::Done;
                return Some(Request::Nmt(NmtCommand::Start));
            }
            Stage::Done | Stage::Failed => return None,
        };
        self.pending = true;
        Some(request)
    }

    /// The node's boot-up message came (or, without a reset, its first
    /// heartbeat in `state`: an operational node is status L, reported and
    /// booted on).
    pub fn boot_up(&mut self, state: NmtState) -> Vec<BootEvent> {
        if self.stage != Stage::AwaitBootUp {
            return Vec::new();
        }
        self.pending = false;
        let mut events = Vec::from([BootEvent::BootedUp]);
        if state == NmtState::Operational {
            events.push(BootEvent::WasOperational);
        }
        self.stage = self.first_identity(0);
        events.extend(self.after_identity());
        events
    }

    /// A wait ([`Request::AwaitBootUp`], [`Request::AwaitHeartbeat`]) ran
    /// out of time.
    pub fn timed_out(&mut self) -> Result<(), BootError> {
        match self.stage {
            Stage::AwaitBootUp => {
                Err(self.fail(BootStatus::NoResponse, Some((0x1000, 0)), None, None, None))
            }
            Stage::Heartbeat => Err(self.fail(
                BootStatus::HeartbeatNotStarted,
                Some((0x1017, 0)),
                None,
                None,
                None,
            )),
            _ => Ok(()),
        }
    }

    /// The node's heartbeat came.
    pub fn heartbeat(&mut self) -> Vec<BootEvent> {
        if self.stage != Stage::Heartbeat {
            return Vec::new();
        }
        self.pending = false;
        self.stage = Stage::Start;
        let mut events = Vec::from([BootEvent::HeartbeatStarted]);
        events.extend(self.finish());
        events
    }

    /// The answer to a [`Request::Read`]: the value (little-endian bytes)
    /// or the abort.
    pub fn read_done(
        &mut self,
        result: Result<&[u8], AbortCode>,
    ) -> Result<Vec<BootEvent>, BootError> {
        if !self.pending {
            return Ok(Vec::new());
        }
        self.pending = false;
        let value = result.map(le_u32);
        match self.stage.clone() {
            Stage::Identity(i) => {
                let (index, sub, status) = IDENTITY[i];
                let expected = self.expected(i);
                match value {
                    // No answer to 0x1000 at all (the SDO timed out): B.
                    Err(AbortCode::Timeout) if i == 0 => Err(self.fail(
                        BootStatus::NoResponse,
                        Some((index, sub)),
                        None,
                        None,
                        Some(AbortCode::Timeout),
                    )),
                    // A refusal is an answer: the node is there. Without
                    // an expected device type that is all the read asks.
                    Err(_) if i == 0 && expected == 0 => {
                        self.stage = self.first_identity(1);
                        Ok(self.after_identity())
                    }
                    // A refused identity read: that entry's status.
                    Err(abort) => Err(self.fail(
                        status,
                        Some((index, sub)),
                        Some(expected),
                        None,
                        Some(abort),
                    )),
                    Ok(found) if expected != 0 && found != expected => Err(self.fail(
                        status,
                        Some((index, sub)),
                        Some(expected),
                        Some(found),
                        None,
                    )),
                    Ok(_) => {
                        self.stage = self.first_identity(i + 1);
                        Ok(self.after_identity())
                    }
                }
            }
            Stage::Software => {
                let expected = self.plan.software_version;
                match value {
                    Ok(found) if found == expected => {
                        self.stage = Stage::ConfigDate;
                        Ok(self.after_software())
                    }
                    Ok(found) => Err(self.fail(
                        BootStatus::SoftwareUpdateNotAllowed,
                        Some((0x1F56, 1)),
                        Some(expected),
                        Some(found),
                        None,
                    )),
                    Err(abort) => Err(self.fail(
                        BootStatus::SoftwareUpdateNotAllowed,
                        Some((0x1F56, 1)),
                        Some(expected),
                        None,
                        Some(abort),
                    )),
                }
            }
            Stage::ConfigDate => {
                // A node without 0x1020 is configured every time.
                match value {
                    Ok(date) => self.stage = Stage::ConfigTime(date),
                    Err(_) => self.stage = Stage::Configure(0),
                }
                Ok(self.after_config_check())
            }
            Stage::ConfigTime(date) => {
                let current = matches!((value, self.plan.configuration_date_time), (Ok(time), Some(want)) if want == (date, time));
                if current {
                    self.stage = Stage::Heartbeat;
                    let mut events = Vec::from([BootEvent::ConfigurationCurrent]);
                    events.extend(self.after_configuration());
                    Ok(events)
                } else {
                    self.stage = Stage::Configure(0);
                    Ok(self.after_config_check())
                }
            }
            _ => Ok(Vec::new()),
        }
    }

    /// The answer to a [`Request::Write`].
    pub fn write_done(
        &mut self,
        result: Result<(), AbortCode>,
    ) -> Result<Vec<BootEvent>, BootError> {
        let Stage::Configure(i) = self.stage else {
            return Ok(Vec::new());
        };
        if !self.pending {
            return Ok(Vec::new());
        }
        self.pending = false;
        if let Err(abort) = result {
            let w = &self.plan.configuration[i];
            let object = Some((w.index, w.sub_index));
            return Err(self.fail(
                BootStatus::ConfigurationFailed,
                object,
                None,
                None,
                Some(abort),
            ));
        }
        self.stage = Stage::Configure(i + 1);
        Ok(self.after_config_check())
    }

    fn expected(&self, i: usize) -> u32 {
        let p = &self.plan;
        [
            p.device_type,
            p.vendor_id,
            p.product_code,
            p.revision_number,
            p.serial_number,
        ][i]
    }

    /// The first identity read from `i` on: the device type is always read
    /// (its answer tells that the node is there), the others only when an
    /// expected value is given; after the last, the software check.
    fn first_identity(&self, i: usize) -> Stage {
        match (i..IDENTITY.len()).find(|&j| j == 0 || self.expected(j) != 0) {
            Some(j) => Stage::Identity(j),
            None => Stage::Software,
        }
    }

    fn after_identity(&mut self) -> Vec<BootEvent> {
        if self.stage != Stage::Software {
            return Vec::new();
        }
        let mut events = Vec::from([BootEvent::IdentityChecked]);
        if self.plan.software_version == 0 {
            self.stage = Stage::ConfigDate;
            events.extend(self.after_software());
        }
        events
    }

    fn after_software(&mut self) -> Vec<BootEvent> {
        if self.plan.configuration_date_time.is_none() {
            self.stage = Stage::Configure(0);
            return self.after_config_check();
        }
        Vec::new()
    }

    /// In [`Stage::Configure`]: past the last write, the configuration is done.
    fn after_config_check(&mut self) -> Vec<BootEvent> {
        match self.stage {
            Stage::Configure(i) if i >= self.plan.configuration.len() => {
                self.stage = Stage::Heartbeat;
                let mut events = Vec::from([BootEvent::Configured { entries: i }]);
                events.extend(self.after_configuration());
                events
            }
            _ => Vec::new(),
        }
    }

    fn after_configuration(&mut self) -> Vec<BootEvent> {
        if self.plan.heartbeat {
            return Vec::new();
        }
        self.stage = Stage::Start;
        self.finish()
    }

    fn finish(&mut self) -> Vec<BootEvent> {
        if !self.plan.start {
            self.stage = Stage::Done;
        }
        Vec::from([BootEvent::Booted])
    }

    fn fail(
        &mut self,
        status: BootStatus,
        object: Option<(u16, u8)>,
        expected: Option<u32>,
        found: Option<u32>,
        abort: Option<AbortCode>,
    ) -> BootError {
        self.stage = Stage::Failed;
        self.pending = false;
        BootError {
            node: self.plan.node,
            status,
            object,
            expected,
            found,
            abort,
        }
    }
}

/// Up to four little-endian bytes as a u32.
fn le_u32(bytes: &[u8]) -> u32 {
    let mut word = [0u8; 4];
    for (slot, byte) in word.iter_mut().zip(bytes) {
        *slot = *byte;
    }
    u32::from_le_bytes(word)
}

#[cfg(test)]
mod tests;
