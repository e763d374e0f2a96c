//! What a CANopen manager needs to boot and run a network: the slaves with
//! what is expected of each ([`SlavePlan`]), how each is supervised, and
//! the master's own part (SYNC, heartbeat, the PDOs it sends and
//! receives). Plain data, `const`-constructible (every list is a
//! [`Cow`]), so a generated network embeds its plan as a constant and a
//! bus file read at run time gives the same value
//! (`eds2rust::network::boot_plan`).

use alloc::borrow::Cow;
use core::num::NonZeroU8;
use core::time::Duration;

use crate::nmt::NmtCommand;
use crate::od::NodeId;

/// One configuration write (an entry of a concise DCF).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ConfigWrite {
    pub index: u16,
    pub sub_index: u8,
    /// The value, little-endian as on the bus.
    pub data: Cow<'static, [u8]>,
}

/// What the network expects of one slave and how to boot it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SlavePlan {
    pub node: NodeId,
    /// 0x1000; 0 is not checked.
    pub device_type: u32,
    /// 0x1018 sub 1–4; 0 is not checked.
    pub vendor_id: u32,
    pub product_code: u32,
    pub revision_number: u32,
    pub serial_number: u32,
    /// 0x1F56 sub 1 expected; 0 is not checked.
    pub software_version: u32,
    /// 0x1020 sub 1 and 2 (date, time) the configuration carries; `None`
    /// always downloads it.
    pub configuration_date_time: Option<(u32, u32)>,
    /// The configuration, in order (a concise DCF's entries).
    pub configuration: Cow<'static, [ConfigWrite]>,
    /// Reset before booting: `Some(ResetCommunication)` or
    /// `Some(ResetNode)`; `None` waits for a boot-up message (or, from a
    /// node already running, a heartbeat).
    pub reset: Option<NmtCommand>,
    /// Wait for a heartbeat before starting (the master consumes one).
    pub heartbeat: bool,
    /// Start the node when it is booted (false: the master starts all
    /// nodes at the end, or none).
    pub start: bool,
}

/// How the master supervises a slave once it is booted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Supervision {
    /// Neither heartbeat nor guarding.
    None,
    /// The master consumes the slave's heartbeat with this consumer time.
    Heartbeat(Duration),
    /// The master guards the slave: a request every `guard_time`, lost
    /// after `guard_time × life_time_factor` without an answer.
    Guarding {
        guard_time: Duration,
        life_time_factor: NonZeroU8,
    },
}

/// One slave of the network.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SlaveConfig {
    /// Its name in the network (the bus file's key).
    pub name: Cow<'static, str>,
    pub plan: SlavePlan,
    /// 0x1F81 bit 2: the master checks and configures it (false: it is
    /// only started and supervised).
    pub boot: bool,
    /// 0x1F81 bit 3: the network does not run without it.
    pub mandatory: bool,
    pub supervision: Supervision,
}

/// A PDO of the master's process image: a slave's TPDO the master
/// receives, or a slave's RPDO the master sends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PdoLink {
    /// The slave it belongs to.
    pub node: NodeId,
    /// The PDO's number on that slave (1-based).
    pub number: u16,
    /// The COB-ID entry (bit 31 set: not valid, not used).
    pub cob_id: u32,
    /// Its transmission type (0–240 synchronous, 254/255 event-driven).
    pub transmission: u8,
    /// Its length in bytes.
    pub len: u8,
    /// Event timer in ms (0: none): the master sends an event-driven PDO
    /// again after it, or reports a received one missing after it.
    pub event_timer: u16,
    /// Inhibit time in units of 100 µs (0: none).
    pub inhibit_time: u16,
}

/// The master's own part of the network.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MasterPlan {
    pub node: NodeId,
    /// Its heartbeat producer time (`None`: no heartbeat).
    pub heartbeat: Option<Duration>,
    /// The SYNC period (`None`: the master produces no SYNC).
    pub sync_period: Option<Duration>,
    /// The SYNC counter overflow value (0: no counter).
    pub sync_overflow: u8,
}

/// A whole network, as a CiA 302-2 manager boots it (0x1F80 NMT start-up,
/// 0x1F81 slave assignment, 0x1F89 boot time, the slaves' expected
/// identities and concise DCFs).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NetworkPlan {
    pub master: MasterPlan,
    /// The slaves, by node id.
    pub slaves: Cow<'static, [SlaveConfig]>,
    /// 0x1F89: the time all mandatory slaves have to boot in (`None`: each
    /// wait for a slave lasts [`NetworkPlan::response_time`]).
    pub boot_time: Option<Duration>,
    /// How long the master waits for a boot-up message or a first
    /// heartbeat when no boot time is given.
    pub response_time: Duration,
    /// 0x1F80 bit 3 clear: the master starts the slaves.
    pub start_nodes: bool,
    /// 0x1F80 bit 1: with one "start all nodes" once every slave's first
    /// boot is over (else each slave when it is booted).
    pub start_all_nodes: bool,
    /// 0x1F80 bit 2 clear: the master enters Operational itself.
    pub start_master: bool,
    /// 0x1F80 bit 4: one "reset communication" to all nodes first, instead
    /// of one per slave.
    pub reset_all_nodes: bool,
    /// 0x1F80 bit 6: a mandatory slave's failure stops all nodes.
    pub stop_all_nodes: bool,
    /// The slaves' TPDOs the master receives.
    pub receive: Cow<'static, [PdoLink]>,
    /// The slaves' RPDOs the master sends.
    pub transmit: Cow<'static, [PdoLink]>,
}

impl NetworkPlan {
    /// The response time used when a plan does not say otherwise.
    pub const DEFAULT_RESPONSE_TIME: Duration = Duration::from_secs(2);

    /// The slave with node id `node`.
    pub fn slave(&self, node: NodeId) -> Option<&SlaveConfig> {
        self.slaves.iter().find(|s| s.plan.node == node)
    }
}
