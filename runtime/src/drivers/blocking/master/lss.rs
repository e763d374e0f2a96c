//! The LSS services of the blocking [`Master`]: each starts a request on
//! the LSS master core and waits for the event that ends it, while every
//! other core keeps running.

use core::fmt;
use core::time::Duration;

use super::Master;
use crate::Instant;
use crate::blocking::{Error, RunError};
use crate::lss::{
    ConfigureService, Identity, IdentityField, KnownIdentity, LssError, LssEvent, LssMaster,
    LssNodeId, LssState,
};
use crate::master::MasterEvent;
use crate::transport::Bus;

/// Timeouts an LSS request may take: fastscan waits out up to 133, plus
/// slack.
const LSS_STEPS: u32 = 140;

/// Why an LSS request of a master failed ([`Error::Lss`]; a bus failure
/// is [`Error::Io`]).
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum LssRequestError {
    /// Another LSS request is still in progress.
    Busy,
    /// No slave answered within the LSS timeout.
    NoResponse,
    /// The slave answered a configuration service with an error.
    Refused {
        /// The service it refused.
        service: ConfigureService,
        /// The error code (1: not supported, 2: storage access, 0xFF:
        /// implementation-specific, see `spec`).
        error: u8,
        /// The implementation-specific error.
        spec: u8,
    },
    /// The request ended with an event that does not answer it.
    Unexpected(LssEvent),
}

impl fmt::Display for LssRequestError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LssRequestError::Busy => f.write_str(
                "an LSS request is already in progress; wait for its event before the next",
            ),
            LssRequestError::NoResponse => f.write_str(
                "no LSS slave answered in time; check that a slave is connected and in the state the request needs",
            ),
            LssRequestError::Refused {
                service,
                error,
                spec,
            } => {
                let service = match service {
                    ConfigureService::NodeId => "configure node id",
                    ConfigureService::BitTiming => "configure bit timing",
                    ConfigureService::Store => "store configuration",
                };
                write!(
                    f,
                    "the LSS slave refused {service}: error {error}, implementation-specific error {spec}"
                )
            }
            LssRequestError::Unexpected(e) => write!(f, "unexpected end of the LSS request: {e:?}"),
        }
    }
}

impl std::error::Error for LssRequestError {}

impl<B: Bus> Master<B> {
    /// Starts an LSS request with `start` (given the LSS core and the
    /// current time) and waits for the event that ends it.
    pub fn lss(
        &mut self,
        start: impl FnOnce(&mut LssMaster, Instant) -> Result<(), LssError>,
    ) -> Result<LssEvent, Error> {
        self.pump();
        let now = self.now();
        start(&mut self.core.lss, now).map_err(|LssError| Error::Lss(LssRequestError::Busy))?;
        let bound = self
            .core
            .lss
            .timeout()
            .saturating_mul(LSS_STEPS)
            .saturating_add(Duration::from_secs(1));
        let deadline = now + bound;
        let result = self.wait(Some(deadline), &mut |event| match event {
            MasterEvent::Lss(e) => Ok(e),
            other => Err(other),
        });
        result.map_err(|e| {
            self.core.lss.cancel();
            match e {
                RunError::Io(e) => Error::Io(e),
                RunError::Deadline | RunError::Stopped => Error::Lss(LssRequestError::NoResponse),
            }
        })
    }

    /// Switch state global: every LSS slave enters `state`.
    pub fn lss_switch_global(&mut self, state: LssState) -> Result<(), Error> {
        let r = self.lss(|lss, now| lss.switch_global(now, state));
        lss_outcome(r, |e| (e == LssEvent::Sent).then_some(()))
    }

    /// Switch state selective: the slave with `identity` enters the
    /// configuration state.
    pub fn lss_switch_selective(&mut self, identity: Identity) -> Result<(), Error> {
        let r = self.lss(|lss, now| lss.switch_selective(now, identity));
        lss_outcome(r, |e| (e == LssEvent::Selected).then_some(()))
    }

    /// Configures the node id of the slave in the configuration state (a
    /// [`NodeId`](crate::od::NodeId), or [`LssNodeId::Unconfigured`]); it takes effect at its
    /// next NMT reset communication.
    pub fn lss_configure_node_id(&mut self, node: impl Into<LssNodeId>) -> Result<(), Error> {
        let node = node.into();
        let r = self.lss(|lss, now| lss.configure_node_id(now, node));
        lss_outcome(r, |e| (e == LssEvent::NodeIdConfigured).then_some(()))
    }

    /// Makes the slave in the configuration state store its configuration.
    pub fn lss_store(&mut self) -> Result<(), Error> {
        let r = self.lss(|lss, now| lss.store_configuration(now));
        lss_outcome(r, |e| (e == LssEvent::Stored).then_some(()))
    }

    /// Inquires one part of the address of the slave in the configuration
    /// state.
    pub fn lss_inquire_identity(&mut self, field: IdentityField) -> Result<u32, Error> {
        let r = self.lss(|lss, now| lss.inquire_identity(now, field));
        lss_outcome(r, |e| match e {
            LssEvent::Identity { field: f, value } if f == field => Some(value),
            _ => None,
        })
    }

    /// Inquires the active node id of the slave in the configuration state
    /// (0xFF: none).
    pub fn lss_inquire_node_id(&mut self) -> Result<u8, Error> {
        let r = self.lss(|lss, now| lss.inquire_node_id(now));
        lss_outcome(r, |e| match e {
            LssEvent::NodeId(id) => Some(id),
            _ => None,
        })
    }

    /// Fastscan: the address of one non-configured slave, now in the
    /// configuration state; `None` when there is none.
    pub fn lss_fastscan(&mut self, known: KnownIdentity) -> Result<Option<Identity>, Error> {
        let r = self.lss(|lss, now| lss.fastscan(now, known));
        lss_outcome(r, |e| match e {
            LssEvent::Found(identity) => Some(Some(identity)),
            LssEvent::NotFound => Some(None),
            _ => None,
        })
    }
}

/// The value of an LSS request's end event, or the error it stands for.
pub(crate) fn lss_outcome<T>(
    result: Result<LssEvent, Error>,
    value: impl FnOnce(LssEvent) -> Option<T>,
) -> Result<T, Error> {
    let event = result?;
    if let Some(v) = value(event) {
        return Ok(v);
    }
    Err(Error::Lss(match event {
        LssEvent::NoResponse => LssRequestError::NoResponse,
        LssEvent::ConfigureFailed {
            service,
            error,
            spec,
        } => LssRequestError::Refused {
            service,
            error,
            spec,
        },
        other => LssRequestError::Unexpected(other),
    }))
}
