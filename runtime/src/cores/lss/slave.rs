//! The LSS slave: answers every CiA 305 service for one device.

use crate::lss::proto::{BIT_CHECK_CONFIRM, FastscanRequest, RangeField, Request, Response};
use crate::lss::{
    BitRate, BitTiming, ERROR_NONE, ERROR_NOT_SUPPORTED, Identity, IdentityField, LssState,
    node_id_byte,
};
use crate::od::NodeId;
use crate::queue::Ring;
use crate::{Frame, Instant, Service};

/// What an [`LssSlave`] tells the device (or simulator) around it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum LssSlaveEvent {
    /// The LSS state changed.
    StateChanged(LssState),
    /// Configure node id set a new pending node id (`None`: unconfigured);
    /// it becomes active at the next NMT reset communication
    /// ([`LssSlave::apply_pending`]).
    NodeIdChanged {
        /// The new pending node id.
        pending: Option<NodeId>,
    },
    /// Configure bit timing set a new pending bit timing.
    BitTimingConfigured(BitTiming),
    /// Activate bit timing: switch to this bit timing after `delay_ms`,
    /// then stay silent for `delay_ms` more (CiA 305).
    BitTimingActivate {
        /// Table selector of the pending bit timing.
        table: u8,
        /// Index in the table.
        index: u8,
        /// The switch delay, in milliseconds.
        delay_ms: u16,
    },
    /// Store configuration: persist [`LssSlave::pending_node_id`] and
    /// [`LssSlave::pending_bit_timing`] (already answered with success).
    StoreRequested,
    /// Switched to waiting after receiving a node id while having none
    /// active: CiA 305 has the device carry out NMT reset communication now
    /// (call [`LssSlave::apply_pending`] and send the boot-up message).
    ResetCommunication,
}

/// Responses kept until polled.
const OUTBOX: usize = 4;
/// Events kept; when full the oldest is dropped.
const EVENTS: usize = 16;

/// Where an identify remote slave sequence stands: the number of its frames
/// matched so far and the lower bounds received.
#[derive(Debug, Clone, Copy, Default)]
struct IdentifyProgress {
    matched: u8,
    revision_low: u32,
    serial_low: u32,
}

/// LSS slave (CiA 305) of one device: its LSS address, pending and active
/// node id and bit timing, and the waiting/configuration state.
///
/// - Waiting state: switch state selective (the four frames 0x40 to 0x43 in
///   order, each matching) and fastscan; configuration state: configure,
///   activate, store and inquire services. Switch state global, identify
///   remote slave and identify non-configured apply in both.
/// - The slave counts as non-configured (identify non-configured, fastscan)
///   while it has neither an active nor a pending node id.
/// - Configure node id accepts 1 to 127 and 0xFF (error 1 otherwise);
///   configure bit timing accepts the supported rates of the CiA 301 table
///   (all by default; error 1 otherwise); store succeeds unless
///   [`LssSlave::set_store_supported`] turned it off (error 1).
#[derive(Debug, Clone)]
pub struct LssSlave {
    identity: Identity,
    state: LssState,
    pending_node: Option<NodeId>,
    active_node: Option<NodeId>,
    pending_timing: BitTiming,
    active_timing: BitTiming,
    /// Bit `i` set: index `i` of the CiA 301 table is supported.
    supported_rates: u16,
    store_supported: bool,
    /// Frames of switch state selective matched so far (0 to 3).
    selected: u8,
    identify: IdentifyProgress,
    /// The LSS sub the fastscan is at in this slave.
    fastscan_sub: u8,
    outbox: Ring<Frame, OUTBOX>,
    events: Ring<LssSlaveEvent, EVENTS>,
}

impl LssSlave {
    /// A slave in the waiting state with address `identity`, node id `node`
    /// (active and pending; `None`: unconfigured) and bit timing `timing`.
    pub const fn new(identity: Identity, node: Option<NodeId>, timing: BitTiming) -> LssSlave {
        LssSlave {
            identity,
            state: LssState::Waiting,
            pending_node: node,
            active_node: node,
            pending_timing: timing,
            active_timing: timing,
            supported_rates: 0b11_1101_1111,
            store_supported: true,
            selected: 0,
            identify: IdentifyProgress {
                matched: 0,
                revision_low: 0,
                serial_low: 0,
            },
            fastscan_sub: 0,
            outbox: Ring::new(),
            events: Ring::new(),
        }
    }

    /// The LSS address.
    pub const fn identity(&self) -> Identity {
        self.identity
    }

    /// The LSS state.
    pub const fn state(&self) -> LssState {
        self.state
    }

    /// The node id in use (`None`: unconfigured).
    pub const fn active_node_id(&self) -> Option<NodeId> {
        self.active_node
    }

    /// The node id set by LSS, active after the next NMT reset
    /// communication (`None`: unconfigured).
    pub const fn pending_node_id(&self) -> Option<NodeId> {
        self.pending_node
    }

    /// The bit timing in use.
    pub const fn active_bit_timing(&self) -> BitTiming {
        self.active_timing
    }

    /// The bit timing set by configure bit timing, active after activate
    /// bit timing.
    pub const fn pending_bit_timing(&self) -> BitTiming {
        self.pending_timing
    }

    /// Makes the pending node id active; the device calls this when it
    /// carries out NMT reset communication (or reset node).
    pub fn apply_pending(&mut self) {
        self.active_node = self.pending_node;
    }

    /// Whether store configuration succeeds (default) or answers error 1
    /// (not supported).
    pub fn set_store_supported(&mut self, supported: bool) {
        self.store_supported = supported;
    }

    /// Whether configure bit timing accepts `rate` (all are by default).
    pub fn set_bit_rate_supported(&mut self, rate: BitRate, supported: bool) {
        let bit = 1u16 << rate.table_index();
        if supported {
            self.supported_rates |= bit;
        } else {
            self.supported_rates &= !bit;
        }
    }

    /// Whether configure bit timing accepts `timing`.
    pub fn supports(&self, timing: BitTiming) -> bool {
        timing.bit_rate().is_some_and(|rate| {
            let bit = 1u16 << rate.table_index();
            self.supported_rates & bit != 0
        })
    }

    /// Whether the slave has neither an active nor a pending node id.
    pub const fn is_non_configured(&self) -> bool {
        self.active_node.is_none() && self.pending_node.is_none()
    }

    /// Events dropped because the event queue was full.
    pub fn dropped_events(&self) -> u32 {
        self.events.dropped()
    }

    fn respond(&mut self, response: Response) {
        self.outbox.push(response.to_frame());
    }

    fn enter(&mut self, state: LssState) {
        self.selected = 0;
        if self.state != state {
            self.state = state;
            self.events.push(LssSlaveEvent::StateChanged(state));
        }
    }

    fn switch_global(&mut self, state: LssState) {
        if state == LssState::Waiting
            && self.state == LssState::Configuration
            && self.active_node.is_none()
            && self.pending_node.is_some()
        {
            self.events.push(LssSlaveEvent::ResetCommunication);
        }
        self.enter(state);
    }

    fn switch_selective(&mut self, field: IdentityField, value: u32) {
        if field == IdentityField::VendorId {
            self.selected = 0;
        }
        let matches = self.selected == field.index() && self.identity.get(field) == value;
        self.selected = if matches { self.selected + 1 } else { 0 };
        if self.selected == 4 {
            self.enter(LssState::Configuration);
            self.respond(Response::SwitchStateSelective);
        }
    }

    fn configure_node_id(&mut self, id: u8) {
        let node = NodeId::new(id);
        if node.is_none() && id != node_id_byte(None) {
            self.respond(Response::ConfigureNodeId {
                error: ERROR_NOT_SUPPORTED,
                spec: 0,
            });
            return;
        }
        if self.pending_node != node {
            self.pending_node = node;
            self.events
                .push(LssSlaveEvent::NodeIdChanged { pending: node });
        }
        self.respond(Response::ConfigureNodeId {
            error: ERROR_NONE,
            spec: 0,
        });
    }

    fn configure_bit_timing(&mut self, timing: BitTiming) {
        let error = if self.supports(timing) {
            if self.pending_timing != timing {
                self.pending_timing = timing;
                self.events.push(LssSlaveEvent::BitTimingConfigured(timing));
            }
            ERROR_NONE
        } else {
            ERROR_NOT_SUPPORTED
        };
        self.respond(Response::ConfigureBitTiming { error, spec: 0 });
    }

    fn store(&mut self) {
        let error = if self.store_supported {
            self.events.push(LssSlaveEvent::StoreRequested);
            ERROR_NONE
        } else {
            ERROR_NOT_SUPPORTED
        };
        self.respond(Response::StoreConfiguration { error, spec: 0 });
    }

    fn identify_remote(&mut self, field: RangeField, value: u32) {
        let progress = &mut self.identify;
        let id = &self.identity;
        if field == RangeField::VendorId {
            progress.matched = 0;
        }
        let in_order = progress.matched == field as u8;
        let matches = in_order
            && match field {
                RangeField::VendorId => id.vendor_id == value,
                RangeField::ProductCode => id.product_code == value,
                RangeField::RevisionLow => {
                    progress.revision_low = value;
                    true
                }
                RangeField::RevisionHigh => (progress.revision_low..=value).contains(&id.revision),
                RangeField::SerialLow => {
                    progress.serial_low = value;
                    true
                }
                RangeField::SerialHigh => (progress.serial_low..=value).contains(&id.serial),
            };
        progress.matched = if matches { progress.matched + 1 } else { 0 };
        if progress.matched == 6 {
            progress.matched = 0;
            self.respond(Response::IdentifySlave);
        }
    }

    fn fastscan(&mut self, scan: FastscanRequest) {
        if self.state != LssState::Waiting || !self.is_non_configured() || !scan.is_valid() {
            return;
        }
        if scan.bit_check == BIT_CHECK_CONFIRM {
            self.fastscan_sub = 0;
            self.respond(Response::IdentifySlave);
            return;
        }
        if scan.sub != self.fastscan_sub {
            return;
        }
        let Some(field) = IdentityField::from_index(scan.sub) else {
            return;
        };
        let mask = u32::MAX.checked_shl(scan.bit_check.into()).unwrap_or(0);
        if self.identity.get(field) & mask != scan.id_number & mask {
            return;
        }
        self.fastscan_sub = scan.next;
        self.respond(Response::IdentifySlave);
        if scan.bit_check == 0 && scan.next < scan.sub {
            self.enter(LssState::Configuration);
        }
    }
}

impl Service for LssSlave {
    type Event = LssSlaveEvent;

    /// Takes LSS requests (COB-ID 0x7E5, 8 bytes); everything else, and
    /// requests not valid in the current state, is ignored.
    fn handle_frame(&mut self, _now: Instant, frame: &Frame) {
        let Some(request) = Request::from_frame(frame) else {
            return;
        };
        let configuring = self.state == LssState::Configuration;
        match request {
            Request::SwitchStateGlobal(state) => self.switch_global(state),
            Request::SwitchStateSelective(field, value) if !configuring => {
                self.switch_selective(field, value);
            }
            Request::IdentifyRemote(field, value) => self.identify_remote(field, value),
            Request::IdentifyNonConfigured if self.is_non_configured() => {
                self.respond(Response::IdentifyNonConfiguredSlave);
            }
            Request::Fastscan(scan) => self.fastscan(scan),
            Request::ConfigureNodeId(id) if configuring => self.configure_node_id(id),
            Request::ConfigureBitTiming { table, index } if configuring => {
                self.configure_bit_timing(BitTiming { table, index });
            }
            Request::ActivateBitTiming { delay_ms } if configuring => {
                self.active_timing = self.pending_timing;
                self.events.push(LssSlaveEvent::BitTimingActivate {
                    table: self.pending_timing.table,
                    index: self.pending_timing.index,
                    delay_ms,
                });
            }
            Request::StoreConfiguration if configuring => self.store(),
            Request::InquireIdentity(field) if configuring => {
                self.respond(Response::InquireIdentity(field, self.identity.get(field)));
            }
            Request::InquireNodeId if configuring => {
                self.respond(Response::InquireNodeId(node_id_byte(self.active_node)));
            }
            _ => {}
        }
    }

    fn poll_transmit(&mut self) -> Option<Frame> {
        self.outbox.pop()
    }

    fn poll_event(&mut self) -> Option<LssSlaveEvent> {
        self.events.pop()
    }
    // The slave keeps no timers (the default `handle_timeout` and
    // `poll_timeout`).
}

#[cfg(test)]
mod tests;
