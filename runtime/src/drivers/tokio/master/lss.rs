//! The LSS services of the tokio [`Master`]: each starts a request on the
//! LSS master core and waits for the event that ends it, while the driver
//! keeps every other core running.

use ::tokio::sync::oneshot;

use super::{Error, LssRequestError, Master, Shared};
use crate::Instant;
use crate::blocking::master::lss::lss_outcome;
use crate::lss::{
    Identity, IdentityField, KnownIdentity, LssError, LssEvent, LssMaster, LssNodeId, LssState,
};

/// Cancels the LSS request of a call dropped before its end.
struct Guard<'a> {
    shared: &'a Shared,
    id: u64,
    armed: bool,
}

impl Drop for Guard<'_> {
    fn drop(&mut self) {
        if !self.armed {
            return;
        }
        let mut state = self.shared.lock();
        if state.lss.as_ref().is_some_and(|(id, _)| *id == self.id) {
            state.lss = None;
            state.core.lss.cancel();
        }
    }
}

impl Master {
    /// Starts an LSS request with `start` (given the LSS core and the
    /// current time) and waits for the event that ends it. Requests take
    /// turns; each ends with one event of the core (which bounds every
    /// step by its timeout, [`LssMaster::timeout`]). Dropping the future
    /// cancels the request.
    pub async fn lss(
        &self,
        start: impl FnOnce(&mut LssMaster, Instant) -> Result<(), LssError>,
    ) -> Result<LssEvent, Error> {
        let _turn = self.shared.lss_turn.lock().await;
        let (reply, id) = {
            let mut state = self.shared.lock();
            state.running()?;
            let now = self.shared.now();
            start(&mut state.core.lss, now)
                .map_err(|LssError| Error::Lss(LssRequestError::Busy))?;
            let (tx, rx) = oneshot::channel();
            let id = state.next_id();
            state.lss = Some((id, tx));
            (rx, id)
        };
        self.shared.wake.notify_one();
        let mut guard = Guard {
            shared: &self.shared,
            id,
            armed: true,
        };
        let result = reply.await;
        guard.armed = false;
        result.map_err(|_| self.shared.lock().stopped_error())
    }

    /// Switch state global: every LSS slave enters `state`.
    pub async fn lss_switch_global(&self, state: LssState) -> Result<(), Error> {
        let r = self.lss(|lss, now| lss.switch_global(now, state)).await;
        lss_outcome(r, |e| (e == LssEvent::Sent).then_some(()))
    }

    /// Switch state selective: the slave with `identity` enters the
    /// configuration state.
    pub async fn lss_switch_selective(&self, identity: Identity) -> Result<(), Error> {
        let r = self
            .lss(|lss, now| lss.switch_selective(now, identity))
            .await;
        lss_outcome(r, |e| (e == LssEvent::Selected).then_some(()))
    }

    /// Configures the node id of the slave in the configuration state (a
    /// node id, or [`LssNodeId::Unconfigured`]); it takes effect at its
    /// next NMT reset communication.
    pub async fn lss_configure_node_id(&self, node: impl Into<LssNodeId>) -> Result<(), Error> {
        let node = node.into();
        let r = self.lss(|lss, now| lss.configure_node_id(now, node)).await;
        lss_outcome(r, |e| (e == LssEvent::NodeIdConfigured).then_some(()))
    }

    /// Makes the slave in the configuration state store its configuration.
    pub async fn lss_store(&self) -> Result<(), Error> {
        let r = self.lss(|lss, now| lss.store_configuration(now)).await;
        lss_outcome(r, |e| (e == LssEvent::Stored).then_some(()))
    }

    /// Inquires one part of the address of the slave in the configuration
    /// state.
    pub async fn lss_inquire_identity(&self, field: IdentityField) -> Result<u32, Error> {
        let r = self.lss(|lss, now| lss.inquire_identity(now, field)).await;
        lss_outcome(r, |e| match e {
            LssEvent::Identity { field: f, value } if f == field => Some(value),
            _ => None,
        })
    }

    /// Inquires the active node id of the slave in the configuration state
    /// (0xFF: none).
    pub async fn lss_inquire_node_id(&self) -> Result<u8, Error> {
        let r = self.lss(|lss, now| lss.inquire_node_id(now)).await;
        lss_outcome(r, |e| match e {
            LssEvent::NodeId(id) => Some(id),
            _ => None,
        })
    }

    /// Fastscan: the address of one non-configured slave, now in the
    /// configuration state; `None` when there is none.
    pub async fn lss_fastscan(&self, known: KnownIdentity) -> Result<Option<Identity>, Error> {
        let r = self.lss(|lss, now| lss.fastscan(now, known)).await;
        lss_outcome(r, |e| match e {
            LssEvent::Found(identity) => Some(Some(identity)),
            LssEvent::NotFound => Some(None),
            _ => None,
        })
    }
}
