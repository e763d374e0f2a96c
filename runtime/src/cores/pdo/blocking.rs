//! Configuring a PDO over a blocking SDO client (`std`):
//! [`configure_pdo`] runs the steps of a [`PdoConfig`].

use core::fmt;
use std::vec::Vec;

use super::config::{ConfigAction, ConfigSession, ReadBackMismatch, Step, StepAction};
use super::{ConfigCheckError, PdoConfig};
use crate::blocking::{Error, SdoClient};
use crate::sdo::{AbortCode, SdoError};
use crate::transport::Bus;

/// Why [`configure_pdo`] failed.
#[derive(Debug)]
#[non_exhaustive]
pub enum PdoConfigError {
    /// The configuration breaks a CiA 301 rule; nothing was sent.
    Invalid(ConfigCheckError),
    /// An SDO access failed (refused by the device, timed out, bus error).
    Transfer {
        /// The step that failed.
        step: Step,
        /// Its 1-based position in the plan.
        number: usize,
        /// Number of steps in the plan.
        total: usize,
        /// The SDO error.
        error: Error,
    },
    /// A value read back differs from the one written: the device accepted
    /// the write but did not keep the value.
    Mismatch(ReadBackMismatch),
}

impl PdoConfigError {
    /// The step that failed (`None` for an invalid configuration).
    pub fn step(&self) -> Option<&Step> {
        match self {
            PdoConfigError::Invalid(_) => None,
            PdoConfigError::Transfer { step, .. } => Some(step),
            PdoConfigError::Mismatch(mismatch) => Some(&mismatch.step),
        }
    }

    /// The abort code that ended a failed SDO access.
    pub fn abort_code(&self) -> Option<AbortCode> {
        match self {
            PdoConfigError::Transfer { error, .. } => error.sdo_error().map(SdoError::code),
            _ => None,
        }
    }

    /// Whether the PDO was left disabled (COB-ID bit 31 set): a write
    /// after the first one (which disables it) failed before the last one
    /// (which enables it again).
    pub fn pdo_left_disabled(&self) -> bool {
        match self {
            PdoConfigError::Transfer { step, number, .. } => {
                step.action() == StepAction::Write && *number > 1
            }
            _ => false,
        }
    }
}

impl fmt::Display for PdoConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PdoConfigError::Invalid(e) => {
                write!(f, "invalid PDO configuration, nothing was sent: {e}")
            }
            PdoConfigError::Transfer {
                step,
                number,
                total,
                error,
            } => {
                write!(
                    f,
                    "PDO configuration step {number} of {total} failed: {step}: "
                )?;
                match error.sdo_error() {
                    Some(SdoError::RemoteAbort(code)) => write!(f, "the device refused: {code}")?,
                    Some(SdoError::Timeout) => f.write_str("the device did not answer in time")?,
                    Some(SdoError::LocalAbort(code)) => {
                        write!(f, "the SDO client aborted the transfer: {code}")?
                    }
                    _ => error.fmt(f)?,
                }
                if self.pdo_left_disabled() {
                    f.write_str("; the PDO is left disabled")?;
                }
                Ok(())
            }
            PdoConfigError::Mismatch(mismatch) => mismatch.fmt(f),
        }
    }
}

impl std::error::Error for PdoConfigError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            PdoConfigError::Invalid(e) => Some(e),
            PdoConfigError::Transfer { error, .. } => Some(error),
            PdoConfigError::Mismatch(e) => Some(e),
        }
    }
}

impl From<ConfigCheckError> for PdoConfigError {
    fn from(e: ConfigCheckError) -> Self {
        PdoConfigError::Invalid(e)
    }
}

/// Configures a PDO of the client's node: checks `config`
/// ([`PdoConfig::check`]), then runs its steps in order (the writes in the
/// CiA 301 order, then the read-backs) and stops at the first failure.
///
/// When a write after the first one fails, the PDO stays disabled (its
/// COB-ID keeps bit 31 set); [`PdoConfigError::pdo_left_disabled`] tells.
pub fn configure_pdo<B: Bus>(
    client: &mut SdoClient<B>,
    config: &PdoConfig<'_>,
) -> Result<(), PdoConfigError> {
    run_steps(client, config)
}

/// One node's objects, read and written over SDO by a blocking driver.
pub(crate) trait SdoAccess {
    /// Writes `data` to (index, sub).
    fn download(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), Error>;
    /// Reads (index, sub).
    fn upload(&mut self, index: u16, sub: u8) -> Result<Vec<u8>, Error>;
}

impl<B: Bus> SdoAccess for SdoClient<B> {
    fn download(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), Error> {
        SdoClient::download(self, index, sub, data)
    }
    fn upload(&mut self, index: u16, sub: u8) -> Result<Vec<u8>, Error> {
        SdoClient::upload(self, index, sub)
    }
}

/// The body of [`configure_pdo`], over any blocking SDO access: a
/// [`ConfigSession`] answered one access at a time.
pub(crate) fn run_steps(
    client: &mut impl SdoAccess,
    config: &PdoConfig<'_>,
) -> Result<(), PdoConfigError> {
    let mut session = ConfigSession::new(config)?;
    loop {
        match session.poll_action() {
            ConfigAction::Write(step) => {
                client
                    .download(step.index(), step.sub(), step.bytes())
                    .map_err(|e| transfer_failed(&session, step, e))?;
                session.on_written();
            }
            ConfigAction::ReadBack(step) => {
                let read = client
                    .upload(step.index(), step.sub())
                    .map_err(|e| transfer_failed(&session, step, e))?;
                session.on_read(&read);
            }
            ConfigAction::Done(result) => return result.map_err(PdoConfigError::Mismatch),
        }
    }
}

/// The error of a failed SDO access of `session`'s step in progress.
pub(crate) fn transfer_failed(
    session: &ConfigSession<'_>,
    step: Step,
    error: Error,
) -> PdoConfigError {
    let (number, total) = session.position();
    PdoConfigError::Transfer {
        step,
        number,
        total,
        error,
    }
}
