//! [`ConfigSession`]: the steps of a [`PdoConfig`] run without I/O.
//!
//! The caller asks [`ConfigSession::poll_action`] what to do until it says
//! [`ConfigAction::Done`]:
//! - [`ConfigAction::Write`]: download [`Step::bytes`] to the step's object,
//!   then call [`ConfigSession::on_written`];
//! - [`ConfigAction::ReadBack`]: upload the step's object, then feed the
//!   bytes to [`ConfigSession::on_read`];
//! - [`ConfigAction::Done`]: every step passed, or a value read back
//!   differed ([`ReadBackMismatch`]).
//!
//! A failed SDO access ends the run: the caller reports it with the step
//! in progress ([`ConfigSession::position`]) and stops asking.
//!
//! ```
//! use eds2rust_runtime::od::PdoDirection;
//! use eds2rust_runtime::pdo::{ConfigAction, ConfigSession, PdoCobId, PdoConfig};
//! use eds2rust_runtime::CanId;
//!
//! let entries = [0x6041_0010];
//! let cob_id = PdoCobId::new(CanId::Standard(0x185));
//! let config = PdoConfig::new(PdoDirection::Tpdo, 1, cob_id, &entries).unwrap();
//! let mut session = ConfigSession::new(&config)?;
//! // A device that keeps what it is given.
//! let mut objects = std::collections::BTreeMap::new();
//! let result = loop {
//!     match session.poll_action() {
//!         ConfigAction::Write(step) => {
//!             objects.insert((step.index(), step.sub()), step.bytes().to_vec());
//!             session.on_written();
//!         }
//!         ConfigAction::ReadBack(step) => {
//!             let read = objects.get(&(step.index(), step.sub())).cloned().unwrap_or_default();
//!             session.on_read(&read);
//!         }
//!         ConfigAction::Done(result) => break result,
//!     }
//! };
//! assert_eq!(result, Ok(()));
//! assert_eq!(objects[&(0x1800, 1)], [0x85, 0x01, 0, 0]);
//! # Ok::<(), eds2rust_runtime::pdo::ConfigCheckError>(())
//! ```

use core::fmt;

use super::{ConfigCheckError, PdoConfig, Step, StepAction, read_value};

/// What a [`ConfigSession`] asks for next.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConfigAction {
    /// Download the step's bytes, then [`ConfigSession::on_written`].
    Write(Step),
    /// Upload the step's object, then [`ConfigSession::on_read`].
    ReadBack(Step),
    /// The configuration ended.
    Done(Result<(), ReadBackMismatch>),
}

/// A value read back differs from the one written: the device accepted the
/// write but did not keep the value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReadBackMismatch {
    /// The read-back step.
    pub step: Step,
    /// Its 1-based position in the plan.
    pub number: usize,
    /// Number of steps in the plan.
    pub total: usize,
    read: [u8; 8],
    len: usize,
}

impl ReadBackMismatch {
    /// The bytes read back (the first 8 of a longer answer).
    pub fn read(&self) -> &[u8] {
        self.read.get(..self.len.min(8)).unwrap_or(&self.read)
    }

    /// The number of bytes read back.
    pub const fn read_len(&self) -> usize {
        self.len
    }
}

impl fmt::Display for ReadBackMismatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let step = &self.step;
        write!(
            f,
            "PDO configuration step {} of {} failed: read back {} (object {:#06X} sub {}): wrote {}, read ",
            self.number,
            self.total,
            step.name(),
            step.index(),
            step.sub(),
            step.format_value(step.value().into())
        )?;
        match read_value(self.read()).filter(|_| self.len <= 8) {
            Some(value) => write!(f, "{}", step.format_value(value))?,
            None => write!(f, "{} bytes {:02X?}", self.len, self.read())?,
        }
        f.write_str("; the device did not keep the value")
    }
}

impl core::error::Error for ReadBackMismatch {}

/// Runs the steps of a [`PdoConfig`] over answers fed by the caller (see
/// the module docs).
#[derive(Debug, Clone)]
pub struct ConfigSession<'c> {
    config: &'c PdoConfig<'c>,
    /// 0-based index of the step in progress (or next).
    at: usize,
    total: usize,
    /// The step in progress waits for its answer.
    waiting: bool,
    mismatch: Option<ReadBackMismatch>,
}

impl<'c> ConfigSession<'c> {
    /// A session for `config`, checked first ([`PdoConfig::check`]):
    /// nothing is to be sent for an invalid configuration.
    pub fn new(config: &'c PdoConfig<'c>) -> Result<ConfigSession<'c>, ConfigCheckError> {
        config.check()?;
        Ok(ConfigSession {
            config,
            at: 0,
            total: config.step_count(),
            waiting: false,
            mismatch: None,
        })
    }

    /// The next thing to do. Asked again before the answer came, it
    /// repeats the step in progress.
    pub fn poll_action(&mut self) -> ConfigAction {
        if let Some(mismatch) = self.mismatch {
            return ConfigAction::Done(Err(mismatch));
        }
        let Some(step) = self.current() else {
            return ConfigAction::Done(Ok(()));
        };
        self.waiting = true;
        match step.action() {
            StepAction::Write => ConfigAction::Write(step),
            StepAction::ReadBack => ConfigAction::ReadBack(step),
        }
    }

    /// The write in progress succeeded. Ignored when no write waits.
    pub fn on_written(&mut self) {
        if self.waiting
            && self
                .current()
                .is_some_and(|s| s.action() == StepAction::Write)
        {
            self.advance();
        }
    }

    /// The read-back in progress returned `data`. Ignored when no
    /// read-back waits.
    pub fn on_read(&mut self, data: &[u8]) {
        let Some(step) = self
            .current()
            .filter(|s| s.action() == StepAction::ReadBack)
        else {
            return;
        };
        if !self.waiting {
            return;
        }
        if step.matches(data) {
            self.advance();
            return;
        }
        let mut read = [0u8; 8];
        for (r, d) in read.iter_mut().zip(data) {
            *r = *d;
        }
        self.waiting = false;
        self.mismatch = Some(ReadBackMismatch {
            step,
            number: self.at + 1,
            total: self.total,
            read,
            len: data.len(),
        });
    }

    /// The 1-based number of the step in progress (or next) and the number
    /// of steps, to report a failed access.
    pub const fn position(&self) -> (usize, usize) {
        (self.at + 1, self.total)
    }

    /// The step in progress (or next); `None` once every step passed.
    pub fn current(&self) -> Option<Step> {
        if self.at >= self.total {
            return None;
        }
        self.config.step(self.at)
    }

    fn advance(&mut self) {
        self.waiting = false;
        self.at += 1;
    }
}
