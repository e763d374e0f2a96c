//! The LSS master: one request at a time, each answered by an event.

use core::fmt;
use core::time::Duration;

use crate::lss::fastscan::{Fastscan, KnownIdentity, Progress};
use crate::lss::proto::{RangeField, Request, Response};
use crate::lss::{
    BitTiming, ERROR_NONE, Identity, IdentityField, IdentityRange, LssNodeId, LssState,
};
use crate::queue::Ring;
use crate::{Frame, Instant, Service};

/// The response timeout of a new [`LssMaster`]. CiA 305 leaves it to the
/// application; fastscan waits it out up to 133 times.
pub const DEFAULT_TIMEOUT: Duration = Duration::from_millis(100);

/// A request was refused: the previous one has not finished (no event yet).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LssError;

impl fmt::Display for LssError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("an LSS request is already in progress; wait for its event")
    }
}

impl core::error::Error for LssError {}

/// The configuration service whose response reported an error.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ConfigureService {
    /// Configure node id (0x11).
    NodeId,
    /// Configure bit timing (0x13).
    BitTiming,
    /// Store configuration (0x17).
    Store,
}

/// The outcome of an [`LssMaster`] request; each request ends with exactly
/// one event (unless cancelled).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum LssEvent {
    /// A request without response (switch state global, activate bit
    /// timing) was handed over by [`Service::poll_transmit`].
    Sent,
    /// Switch state selective: the addressed slave is in the configuration
    /// state.
    Selected,
    /// Configure node id succeeded; the id is pending in the slave until its
    /// next NMT reset communication.
    NodeIdConfigured,
    /// Configure bit timing succeeded.
    BitTimingConfigured,
    /// Store configuration succeeded.
    Stored,
    /// A configuration service answered with an error code.
    ConfigureFailed {
        /// The service that failed.
        service: ConfigureService,
        /// Error code (see [`crate::lss::ERROR_NOT_SUPPORTED`] and the
        /// other constants).
        error: u8,
        /// Implementation-specific error (meaningful with error 0xFF).
        spec: u8,
    },
    /// Inquire identity: one part of the slave's address.
    Identity {
        /// The part asked for.
        field: IdentityField,
        /// Its value.
        value: u32,
    },
    /// Inquire node id: the slave's active node id (0xFF: none).
    NodeId(u8),
    /// Identify remote slave or identify non-configured: at least one slave
    /// answered within the timeout.
    SlavePresent,
    /// No (matching) answer within the timeout.
    NoResponse,
    /// Fastscan found this slave; it is now in the configuration state.
    Found(Identity),
    /// Fastscan found no non-configured slave in the waiting state.
    NotFound,
}

/// Most frames one request sends (identify remote slave).
const MAX_FRAMES: usize = 6;
/// Events kept; one request produces one, so a few are plenty.
const EVENTS: usize = 8;

/// The answer a confirmed request waits for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Expect {
    Selected,
    NodeId,
    BitTiming,
    Store,
    Identity(IdentityField),
    InquiredNodeId,
}

/// The request in progress.
#[derive(Debug, Clone, Copy)]
enum Pending {
    /// No response: done once sent.
    Unconfirmed,
    /// The first matching answer completes it.
    Confirmed(Expect),
    /// Any number of slaves may answer: the whole timeout is waited out.
    Identify {
        /// Identify non-configured (0x50 answers) rather than remote (0x4F).
        non_configured: bool,
    },
    /// The fastscan search; each step waits out the timeout.
    Fastscan(Fastscan),
}

/// LSS master (CiA 305): sends one request at a time and reports its
/// outcome as one [`LssEvent`].
///
/// Answers count only once every frame of the request has been polled, and
/// must arrive before the timeout (measured from the request, or for each
/// fastscan step from the previous step's end). Services any number of
/// slaves may answer (identify, fastscan) always wait out the whole timeout,
/// since answers carry nothing that tells one round from the next.
#[derive(Debug, Clone)]
pub struct LssMaster {
    timeout: Duration,
    pending: Option<Pending>,
    deadline: Option<Instant>,
    /// Every frame of the request has been polled.
    sent: bool,
    /// A matching answer arrived (identify, fastscan).
    answered: bool,
    frames: [Frame; MAX_FRAMES],
    queued: usize,
    polled: usize,
    events: Ring<LssEvent, EVENTS>,
}

default_is_new!(LssMaster);

impl LssMaster {
    /// An idle master with [`DEFAULT_TIMEOUT`].
    pub const fn new() -> LssMaster {
        LssMaster::with_timeout(DEFAULT_TIMEOUT)
    }

    /// An idle master waiting `timeout` for each response.
    pub const fn with_timeout(timeout: Duration) -> LssMaster {
        LssMaster {
            timeout,
            pending: None,
            deadline: None,
            sent: false,
            answered: false,
            frames: [Request::StoreConfiguration.to_frame(); MAX_FRAMES],
            queued: 0,
            polled: 0,
            events: Ring::new(),
        }
    }

    /// The response timeout.
    pub const fn timeout(&self) -> Duration {
        self.timeout
    }

    /// Changes the response timeout (used from the next request or
    /// fastscan step on).
    pub fn set_timeout(&mut self, timeout: Duration) {
        self.timeout = timeout;
    }

    /// Whether no request is in progress (a new one would be accepted).
    pub const fn is_idle(&self) -> bool {
        self.pending.is_none()
    }

    /// Abandons the request in progress without an event; its frames not
    /// yet polled are dropped.
    pub fn cancel(&mut self) {
        self.finish();
    }

    /// Events dropped because the event queue was full.
    pub fn dropped_events(&self) -> u32 {
        self.events.dropped()
    }

    /// Switch state global: every slave enters `state`. No response; ends
    /// with [`LssEvent::Sent`].
    pub fn switch_global(&mut self, now: Instant, state: LssState) -> Result<(), LssError> {
        self.start(
            now,
            Pending::Unconfirmed,
            &[Request::SwitchStateGlobal(state)],
        )
    }

    /// Switch state selective: the slave with address `identity` enters the
    /// configuration state. Ends with [`LssEvent::Selected`] or
    /// [`LssEvent::NoResponse`].
    pub fn switch_selective(&mut self, now: Instant, identity: Identity) -> Result<(), LssError> {
        let frames = IdentityField::ALL
            .map(|field| Request::SwitchStateSelective(field, identity.get(field)));
        self.start(now, Pending::Confirmed(Expect::Selected), &frames)
    }

    /// Configure node id of the slave in the configuration state: a
    /// [`NodeId`](crate::od::NodeId), or [`LssNodeId::Unconfigured`] (0xFF). Ends with
    /// [`LssEvent::NodeIdConfigured`], [`LssEvent::ConfigureFailed`] or
    /// [`LssEvent::NoResponse`].
    pub fn configure_node_id(
        &mut self,
        now: Instant,
        node: impl Into<LssNodeId>,
    ) -> Result<(), LssError> {
        let request = Request::ConfigureNodeId(node.into().to_byte());
        self.start(now, Pending::Confirmed(Expect::NodeId), &[request])
    }

    /// Configure bit timing. Ends with [`LssEvent::BitTimingConfigured`],
    /// [`LssEvent::ConfigureFailed`] or [`LssEvent::NoResponse`].
    pub fn configure_bit_timing(
        &mut self,
        now: Instant,
        timing: BitTiming,
    ) -> Result<(), LssError> {
        let request = Request::ConfigureBitTiming {
            table: timing.table,
            index: timing.index,
        };
        self.start(now, Pending::Confirmed(Expect::BitTiming), &[request])
    }

    /// Activate bit timing: slaves in the configuration state switch to
    /// their pending bit timing after `delay_ms` (and wait as long again
    /// before sending). No response; ends with [`LssEvent::Sent`]. The
    /// caller switches its own interface in the meantime.
    pub fn activate_bit_timing(&mut self, now: Instant, delay_ms: u16) -> Result<(), LssError> {
        self.start(
            now,
            Pending::Unconfirmed,
            &[Request::ActivateBitTiming { delay_ms }],
        )
    }

    /// Store configuration. Ends with [`LssEvent::Stored`],
    /// [`LssEvent::ConfigureFailed`] or [`LssEvent::NoResponse`].
    pub fn store_configuration(&mut self, now: Instant) -> Result<(), LssError> {
        let pending = Pending::Confirmed(Expect::Store);
        self.start(now, pending, &[Request::StoreConfiguration])
    }

    /// Inquire one part of the address of the slave in the configuration
    /// state. Ends with [`LssEvent::Identity`] or [`LssEvent::NoResponse`].
    pub fn inquire_identity(&mut self, now: Instant, field: IdentityField) -> Result<(), LssError> {
        let pending = Pending::Confirmed(Expect::Identity(field));
        self.start(now, pending, &[Request::InquireIdentity(field)])
    }

    /// Inquire the active node id of the slave in the configuration state.
    /// Ends with [`LssEvent::NodeId`] or [`LssEvent::NoResponse`].
    pub fn inquire_node_id(&mut self, now: Instant) -> Result<(), LssError> {
        let pending = Pending::Confirmed(Expect::InquiredNodeId);
        self.start(now, pending, &[Request::InquireNodeId])
    }

    /// Identify remote slave: do slaves within `range` exist? Waits out the
    /// timeout; ends with [`LssEvent::SlavePresent`] or
    /// [`LssEvent::NoResponse`].
    pub fn identify_remote(&mut self, now: Instant, range: IdentityRange) -> Result<(), LssError> {
        let value = |field| match field {
            RangeField::VendorId => range.vendor_id,
            RangeField::ProductCode => range.product_code,
            RangeField::RevisionLow => range.revision_low,
            RangeField::RevisionHigh => range.revision_high,
            RangeField::SerialLow => range.serial_low,
            RangeField::SerialHigh => range.serial_high,
        };
        let frames = RangeField::ALL.map(|field| Request::IdentifyRemote(field, value(field)));
        let pending = Pending::Identify {
            non_configured: false,
        };
        self.start(now, pending, &frames)
    }

    /// Identify non-configured remote slave: do slaves without node id
    /// exist? Waits out the timeout; ends with [`LssEvent::SlavePresent`]
    /// or [`LssEvent::NoResponse`].
    pub fn identify_non_configured(&mut self, now: Instant) -> Result<(), LssError> {
        let pending = Pending::Identify {
            non_configured: true,
        };
        self.start(now, pending, &[Request::IdentifyNonConfigured])
    }

    /// Fastscan: finds the address of one non-configured slave in the
    /// waiting state (the one with the lowest address if several) and puts
    /// it in the configuration state. Parts in `known` are verified instead
    /// of scanned. Ends with [`LssEvent::Found`] or [`LssEvent::NotFound`],
    /// after up to 133 timeouts.
    pub fn fastscan(&mut self, now: Instant, known: KnownIdentity) -> Result<(), LssError> {
        let scan = Fastscan::new(known);
        let request = Request::Fastscan(scan.request());
        self.start(now, Pending::Fastscan(scan), &[request])
    }

    fn start(
        &mut self,
        now: Instant,
        pending: Pending,
        requests: &[Request],
    ) -> Result<(), LssError> {
        if self.pending.is_some() {
            return Err(LssError);
        }
        self.pending = Some(pending);
        self.queue(now, requests);
        if matches!(pending, Pending::Unconfirmed) {
            self.deadline = None;
        }
        Ok(())
    }

    /// Replaces the outgoing frames and restarts the timeout at `now`.
    fn queue(&mut self, now: Instant, requests: &[Request]) {
        self.queued = 0;
        self.polled = 0;
        for (slot, request) in self.frames.iter_mut().zip(requests) {
            *slot = request.to_frame();
            self.queued += 1;
        }
        self.sent = false;
        self.answered = false;
        self.deadline = Some(now + self.timeout);
    }

    fn finish(&mut self) {
        self.pending = None;
        self.deadline = None;
        self.queued = 0;
        self.polled = 0;
        self.sent = false;
        self.answered = false;
    }

    fn complete(&mut self, event: LssEvent) {
        self.finish();
        self.events.push(event);
    }
}

/// The event `response` completes `expect` with, if it answers it.
fn outcome(expect: Expect, response: Response) -> Option<LssEvent> {
    let configured = |service, error, spec, success| {
        if error == ERROR_NONE {
            success
        } else {
            LssEvent::ConfigureFailed {
                service,
                error,
                spec,
            }
        }
    };
    let event = match (expect, response) {
        (Expect::Selected, Response::SwitchStateSelective) => LssEvent::Selected,
        (Expect::NodeId, Response::ConfigureNodeId { error, spec }) => configured(
            ConfigureService::NodeId,
            error,
            spec,
            LssEvent::NodeIdConfigured,
        ),
        (Expect::BitTiming, Response::ConfigureBitTiming { error, spec }) => configured(
            ConfigureService::BitTiming,
            error,
            spec,
            LssEvent::BitTimingConfigured,
        ),
        (Expect::Store, Response::StoreConfiguration { error, spec }) => {
            configured(ConfigureService::Store, error, spec, LssEvent::Stored)
        }
        (Expect::Identity(asked), Response::InquireIdentity(field, value)) if asked == field => {
            LssEvent::Identity { field, value }
        }
        (Expect::InquiredNodeId, Response::InquireNodeId(id)) => LssEvent::NodeId(id),
        _ => return None,
    };
    Some(event)
}

impl Service for LssMaster {
    type Event = LssEvent;

    /// Takes LSS responses (COB-ID 0x7E4) that answer the request in
    /// progress; everything else is ignored.
    fn handle_frame(&mut self, _now: Instant, frame: &Frame) {
        if !self.sent {
            return;
        }
        let Some(response) = Response::from_frame(frame) else {
            return;
        };
        match self.pending {
            Some(Pending::Confirmed(expect)) => {
                if let Some(event) = outcome(expect, response) {
                    self.complete(event);
                }
            }
            Some(Pending::Identify { non_configured }) => {
                let expected = if non_configured {
                    Response::IdentifyNonConfiguredSlave
                } else {
                    Response::IdentifySlave
                };
                self.answered |= response == expected;
            }
            Some(Pending::Fastscan(_)) => {
                self.answered |= response == Response::IdentifySlave;
            }
            Some(Pending::Unconfirmed) | None => {}
        }
    }

    fn handle_timeout(&mut self, now: Instant) {
        let Some(deadline) = self.deadline else {
            return;
        };
        if now < deadline {
            return;
        }
        match self.pending {
            Some(Pending::Confirmed(_)) => self.complete(LssEvent::NoResponse),
            Some(Pending::Identify { .. }) => {
                let event = if self.answered {
                    LssEvent::SlavePresent
                } else {
                    LssEvent::NoResponse
                };
                self.complete(event);
            }
            Some(Pending::Fastscan(mut scan)) => {
                let answered = self.answered && self.sent;
                match scan.advance(answered) {
                    Progress::Continue => {
                        self.pending = Some(Pending::Fastscan(scan));
                        self.queue(now, &[Request::Fastscan(scan.request())]);
                    }
                    Progress::Found(identity) => self.complete(LssEvent::Found(identity)),
                    Progress::NotFound => self.complete(LssEvent::NotFound),
                }
            }
            Some(Pending::Unconfirmed) | None => self.deadline = None,
        }
    }

    fn poll_transmit(&mut self) -> Option<Frame> {
        if self.polled >= self.queued {
            return None;
        }
        let frame = *self.frames.get(self.polled)?;
        self.polled += 1;
        if self.polled >= self.queued {
            self.sent = true;
            if matches!(self.pending, Some(Pending::Unconfirmed)) {
                self.complete(LssEvent::Sent);
            }
        }
        Some(frame)
    }

    fn poll_event(&mut self) -> Option<LssEvent> {
        self.events.pop()
    }

    fn poll_timeout(&self) -> Option<Instant> {
        self.deadline
    }
}

#[cfg(test)]
mod tests;
