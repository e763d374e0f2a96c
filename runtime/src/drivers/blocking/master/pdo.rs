//! PDO calls of the blocking [`Master`]: configuring a device's PDO over
//! SDO, sending and receiving typed PDOs. The tokio master has the same
//! calls with the same arguments.

use core::time::Duration;
use std::vec::Vec;

use super::Master;
use crate::blocking::{Error, RunError};
use crate::master::MasterEvent;
use crate::od::{self, NodeId, PdoLengthError};
use crate::pdo::blocking::{SdoAccess, run_steps};
use crate::pdo::{self, PdoCobId, PdoConfig, PdoError, PdoEvent};
use crate::transport::Bus;

impl<B: Bus> Master<B> {
    /// Configures a PDO of `node` as [`crate::pdo::blocking::configure_pdo`]
    /// does (same steps, read-backs and errors).
    pub fn configure_pdo(&mut self, node: NodeId, config: &PdoConfig<'_>) -> Result<(), Error> {
        run_steps(&mut NodeSdo { master: self, node }, config).map_err(Error::from)
    }

    /// Sends `pdo` to `node` on `P`'s default COB-ID (see
    /// [`Master::send_pdo_on`]).
    pub fn send_pdo<P: od::Pdo>(&mut self, node: NodeId, pdo: &P) -> Result<(), Error> {
        let cob_id = pdo::default_cob_id::<P>(node)?;
        self.send_pdo_on(cob_id, pdo)
    }

    /// Sends `pdo` on `cob_id` through the master's transmitter on that
    /// identifier ([`crate::master::Master::set_pdo`]: an event-driven one
    /// is added when there is none), then sends what the cores have ready:
    /// an event-driven PDO goes out now, a synchronous one at its SYNC.
    pub fn send_pdo_on<P: od::Pdo>(&mut self, cob_id: PdoCobId, pdo: &P) -> Result<(), Error> {
        let now = self.now();
        self.core.set_pdo(now, cob_id, pdo)?;
        self.flush()?;
        Ok(())
    }

    /// The next `P` that `node` sends on its default COB-ID after this
    /// call, waiting at most `timeout` (see [`Master::next_pdo_on`]).
    pub fn next_pdo<P: od::Pdo>(&mut self, node: NodeId, timeout: Duration) -> Result<P, Error> {
        let cob_id = pdo::default_cob_id::<P>(node)?;
        self.next_pdo_on(cob_id, timeout)
    }

    /// The next `P` received on `cob_id` after this call, waiting at most
    /// `timeout` while all the cores run; the PDO is watched first if it
    /// was not (with length [`od::Pdo::LEN`]). The PDO's event is taken;
    /// the other events stay queued. A frame of another length fails with
    /// [`PdoError::Length`] (in [`Error::Pdo`]).
    pub fn next_pdo_on<P: od::Pdo>(
        &mut self,
        cob_id: PdoCobId,
        timeout: Duration,
    ) -> Result<P, Error> {
        let can_id = self.core.watch_pdo::<P>(cob_id)?;
        let deadline = self.now() + timeout;
        let got = self.wait(Some(deadline), &mut |event| {
            let data = match &event {
                MasterEvent::Pdo(PdoEvent::Received {
                    can_id: id,
                    data,
                    len,
                    ..
                }) if *id == can_id => P::decode(data.get(..*len).unwrap_or(&[])),
                MasterEvent::Pdo(PdoEvent::LengthError {
                    can_id: id,
                    expected,
                    actual,
                }) if *id == can_id => Err(PdoLengthError {
                    expected: *expected,
                    actual: *actual,
                }),
                _ => return Err(event),
            };
            Ok(data)
        });
        match got {
            Ok(Ok(pdo)) => Ok(pdo),
            Ok(Err(error)) => Err(PdoError::Length { can_id, error }.into()),
            Err(RunError::Io(e)) => Err(Error::Io(e)),
            Err(RunError::Deadline | RunError::Stopped) => Err(PdoError::Timeout {
                can_id,
                waited: timeout,
            }
            .into()),
        }
    }

    /// The last `P` received from `node` on its default COB-ID (see
    /// [`Master::latest_pdo_on`]).
    pub fn latest_pdo<P: od::Pdo>(&mut self, node: NodeId) -> Result<Option<P>, Error> {
        let cob_id = pdo::default_cob_id::<P>(node)?;
        self.latest_pdo_on(cob_id)
    }

    /// The last `P` received on `cob_id` (`None` before the first); the
    /// PDO is watched from now on if it was not. Takes in what was received
    /// meanwhile without waiting ([`Master::poll`]).
    pub fn latest_pdo_on<P: od::Pdo>(&mut self, cob_id: PdoCobId) -> Result<Option<P>, Error> {
        let can_id = self.core.watch_pdo::<P>(cob_id)?;
        self.poll()?;
        match self.core.pdo_rx.latest::<P>(can_id) {
            None => Ok(None),
            Some(Ok(pdo)) => Ok(Some(pdo)),
            Some(Err(error)) => Err(PdoError::Length { can_id, error }.into()),
        }
    }
}

/// One node's objects through a [`Master`], for the PDO configuration.
struct NodeSdo<'a, B> {
    master: &'a mut Master<B>,
    node: NodeId,
}

impl<B: Bus> SdoAccess for NodeSdo<'_, B> {
    fn download(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), Error> {
        self.master.download(self.node, index, sub, data)
    }
    fn upload(&mut self, index: u16, sub: u8) -> Result<Vec<u8>, Error> {
        self.master.upload(self.node, index, sub)
    }
}
