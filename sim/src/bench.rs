//! A master and simulated devices on one in-process bus in virtual time,
//! for tests: no threads, no sleeping, every frame recorded with its time.
//! Frames are delivered in the order they were sent, at the instant they
//! were sent (a bus without transmission delay).

use std::collections::VecDeque;
use std::time::Duration;

use eds2rust_runtime::master::{Master, MasterEvent};
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::sdo::SdoError;
use eds2rust_runtime::sdo::client::ClientEvent;
use eds2rust_runtime::{Frame, Instant, Service};

use crate::{Behaviour, Device, SimEvent};

/// One master and one simulated device in virtual time.
#[derive(Debug)]
pub struct Bench<B: Behaviour> {
    now: Instant,
    /// The master core.
    pub master: Master,
    /// The simulated device.
    pub device: Device<B>,
    /// Every frame on the bus with the time it was sent.
    pub trace: Vec<(Instant, Frame)>,
    /// Master events not yet taken.
    pub master_events: VecDeque<MasterEvent>,
    /// Device events not yet taken.
    pub device_events: VecDeque<SimEvent<B::Event>>,
}

/// The most frames exchanged at one instant before the bench gives up (a
/// loop between master and device would otherwise never end).
const MAX_FRAMES_PER_INSTANT: usize = 10_000;

impl<B: Behaviour> Bench<B> {
    /// A bench at `now`; the master is started (heartbeat, SYNC).
    pub fn new(mut master: Master, device: Device<B>, now: Instant) -> Self {
        master.start(now);
        let mut bench = Bench {
            now,
            master,
            device,
            trace: Vec::new(),
            master_events: VecDeque::new(),
            device_events: VecDeque::new(),
        };
        bench.exchange();
        bench
    }

    /// The virtual time.
    pub fn now(&self) -> Instant {
        self.now
    }

    /// Sends `frame` from outside (a third node) at the current time.
    pub fn inject(&mut self, frame: &Frame) {
        self.trace.push((self.now, *frame));
        self.master.handle_frame(self.now, frame);
        self.device.handle_frame(self.now, frame);
        self.exchange();
    }

    /// Delivers every pending frame to the other side and collects events,
    /// until both sides are quiet.
    fn exchange(&mut self) {
        for _ in 0..MAX_FRAMES_PER_INSTANT {
            let mut moved = false;
            while let Some(f) = self.master.poll_transmit() {
                self.trace.push((self.now, f));
                self.device.handle_frame(self.now, &f);
                moved = true;
            }
            while let Some(f) = self.device.poll_transmit() {
                self.trace.push((self.now, f));
                self.master.handle_frame(self.now, &f);
                moved = true;
            }
            while let Some(e) = self.master.poll_event() {
                self.master_events.push_back(e);
            }
            while let Some(e) = self.device.poll_event() {
                self.device_events.push_back(e);
                moved = true;
            }
            if !moved {
                return;
            }
        }
    }

    /// Runs until `now + duration`, firing every timer on its instant.
    pub fn run_for(&mut self, duration: Duration) {
        let end = self.now + duration;
        self.run_to(end, |_| false);
    }

    /// Runs until `stop` holds for a master event (which stays queued) or
    /// `limit` has passed; returns whether `stop` held.
    pub fn run_until(
        &mut self,
        limit: Duration,
        mut stop: impl FnMut(&MasterEvent) -> bool,
    ) -> bool {
        let end = self.now + limit;
        self.run_to(end, &mut stop)
    }

    fn run_to(&mut self, end: Instant, mut stop: impl FnMut(&MasterEvent) -> bool) -> bool {
        let mut seen = 0;
        loop {
            self.exchange();
            if self.master_events.iter().skip(seen).any(&mut stop) {
                return true;
            }
            seen = self.master_events.len();
            let next = [self.master.poll_timeout(), self.device.poll_timeout()]
                .into_iter()
                .flatten()
                .min();
            match next {
                Some(at) if at <= end => {
                    self.now = self.now.max(at);
                    if self.master.poll_timeout().is_some_and(|t| t <= self.now) {
                        self.master.handle_timeout(self.now);
                    }
                    if self.device.poll_timeout().is_some_and(|t| t <= self.now) {
                        self.device.handle_timeout(self.now);
                    }
                }
                _ => {
                    self.now = self.now.max(end);
                    self.exchange();
                    return false;
                }
            }
        }
    }

    /// An SDO upload from `node` (on its default channel), in virtual time.
    pub fn upload(&mut self, node: NodeId, index: u16, sub: u8) -> Result<Vec<u8>, SdoError> {
        let now = self.now;
        if self
            .master
            .sdo_or_default(node)
            .upload(now, index, sub)
            .is_err()
        {
            return Err(SdoError::Timeout);
        }
        match self.wait_sdo(node)? {
            ClientEvent::Uploaded { data, .. } => Ok(data),
            _ => Err(SdoError::Timeout),
        }
    }

    /// An SDO download to `node`, in virtual time.
    pub fn download(
        &mut self,
        node: NodeId,
        index: u16,
        sub: u8,
        data: &[u8],
    ) -> Result<(), SdoError> {
        let now = self.now;
        if self
            .master
            .sdo_or_default(node)
            .download(now, index, sub, data)
            .is_err()
        {
            return Err(SdoError::Timeout);
        }
        self.wait_sdo(node).map(|_| ())
    }

    fn wait_sdo(&mut self, node: NodeId) -> Result<ClientEvent, SdoError> {
        let done = |e: &MasterEvent| matches!(e, MasterEvent::Sdo(n, _) if *n == node);
        if !self.run_until(Duration::from_secs(5), done) {
            return Err(SdoError::Timeout);
        }
        let i = self
            .master_events
            .iter()
            .position(done)
            .ok_or(SdoError::Timeout)?;
        match self.master_events.remove(i) {
            Some(MasterEvent::Sdo(_, ClientEvent::Failed { error, .. })) => Err(error),
            Some(MasterEvent::Sdo(_, event)) => Ok(event),
            _ => Err(SdoError::Timeout),
        }
    }

    /// The frames on the bus in candump's compact form, one per entry.
    pub fn trace_lines(&self) -> Vec<String> {
        self.trace.iter().map(|(_, f)| f.to_string()).collect()
    }
}
