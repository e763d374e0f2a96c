//! PDO calls of the tokio [`Master`]: configuring a device's PDO over SDO,
//! sending and receiving typed PDOs, with the names and arguments of the
//! blocking master's.

use core::time::Duration;

use super::Master;
use crate::blocking::Error;
use crate::od::{self, NodeId};
use crate::pdo::blocking::{PdoConfigError, transfer_failed};
use crate::pdo::{self, ConfigAction, ConfigSession, PdoCobId, PdoConfig, PdoError};

impl Master {
    /// Configures a PDO of `node` as [`crate::pdo::blocking::configure_pdo`]
    /// does: the same [`ConfigSession`] (nothing is sent for an invalid
    /// configuration, the writes in the CiA 301 order, the read-backs), and
    /// the same errors.
    pub async fn configure_pdo(&self, node: NodeId, config: &PdoConfig<'_>) -> Result<(), Error> {
        let mut session = ConfigSession::new(config).map_err(PdoConfigError::from)?;
        loop {
            match session.poll_action() {
                ConfigAction::Write(step) => {
                    self.download(node, step.index(), step.sub(), step.bytes())
                        .await
                        .map_err(|e| transfer_failed(&session, step, e))?;
                    session.on_written();
                }
                ConfigAction::ReadBack(step) => {
                    let read = self
                        .upload(node, step.index(), step.sub())
                        .await
                        .map_err(|e| transfer_failed(&session, step, e))?;
                    session.on_read(&read);
                }
                ConfigAction::Done(result) => {
                    return result.map_err(|e| PdoConfigError::Mismatch(e).into());
                }
            }
        }
    }

    /// Sends `pdo` to `node` on `P`'s default COB-ID (see
    /// [`Master::send_pdo_on`]).
    pub fn send_pdo<P: od::Pdo>(&self, node: NodeId, pdo: &P) -> Result<(), Error> {
        let cob_id = pdo::default_cob_id::<P>(node)?;
        self.send_pdo_on(cob_id, pdo)
    }

    /// Sends `pdo` on `cob_id` through the master's transmitter on that
    /// identifier ([`crate::master::Master::set_pdo`]: an event-driven one
    /// is added when there is none) and wakes the driver: an event-driven
    /// PDO goes out now, a synchronous one at its SYNC.
    pub fn send_pdo_on<P: od::Pdo>(&self, cob_id: PdoCobId, pdo: &P) -> Result<(), Error> {
        let now = self.now();
        let mut state = self.shared.lock();
        state.running()?;
        state.core.set_pdo(now, cob_id, pdo)?;
        drop(state);
        self.shared.wake.notify_one();
        Ok(())
    }

    /// The next `P` that `node` sends on its default COB-ID after this
    /// call, waiting at most `timeout` (see [`Master::next_pdo_on`]).
    pub async fn next_pdo<P: od::Pdo>(&self, node: NodeId, timeout: Duration) -> Result<P, Error> {
        let cob_id = pdo::default_cob_id::<P>(node)?;
        self.next_pdo_on(cob_id, timeout).await
    }

    /// The next `P` received on `cob_id` after this call, waiting at most
    /// `timeout` (tokio's clock); the PDO is watched first if it was not
    /// (with length [`od::Pdo::LEN`]). A frame of another length fails
    /// with [`PdoError::Length`] (in [`Error::Pdo`]).
    pub async fn next_pdo_on<P: od::Pdo>(
        &self,
        cob_id: PdoCobId,
        timeout: Duration,
    ) -> Result<P, Error> {
        let mut pdos = self.pdos_on::<P>(cob_id)?;
        let can_id = pdos.can_id();
        match ::tokio::time::timeout(timeout, pdos.next()).await {
            Ok(Some(Ok(pdo))) => Ok(pdo),
            Ok(Some(Err(error))) => Err(PdoError::Length { can_id, error }.into()),
            Ok(None) => Err(self.shared.lock().stopped_error()),
            Err(_) => Err(PdoError::Timeout {
                can_id,
                waited: timeout,
            }
            .into()),
        }
    }

    /// The last `P` received from `node` on its default COB-ID (see
    /// [`Master::latest_pdo_on`]).
    pub fn latest_pdo<P: od::Pdo>(&self, node: NodeId) -> Result<Option<P>, Error> {
        let cob_id = pdo::default_cob_id::<P>(node)?;
        self.latest_pdo_on(cob_id)
    }

    /// The last `P` received on `cob_id` (`None` before the first); the
    /// PDO is watched from now on if it was not.
    pub fn latest_pdo_on<P: od::Pdo>(&self, cob_id: PdoCobId) -> Result<Option<P>, Error> {
        let mut state = self.shared.lock();
        let can_id = state.core.watch_pdo::<P>(cob_id)?;
        let latest = state.core.pdo_rx.latest::<P>(can_id);
        drop(state);
        self.shared.wake.notify_one();
        match latest {
            None => Ok(None),
            Some(Ok(pdo)) => Ok(Some(pdo)),
            Some(Err(error)) => Err(PdoError::Length { can_id, error }.into()),
        }
    }
}
