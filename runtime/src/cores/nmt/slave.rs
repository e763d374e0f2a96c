//! The NMT slave state machine of one node (CiA 301).

use super::{NmtCommand, NmtState, parse_command};
use crate::od::NodeId;
use crate::queue::Ring;
use crate::{Frame, Instant, Service};

/// What an [`NmtSlave`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum NmtSlaveEvent {
    /// The node's state changed.
    StateChanged {
        /// The state before.
        from: NmtState,
        /// The state now.
        to: NmtState,
    },
    /// A reset-node command arrived: the application must reset everything,
    /// then call [`NmtSlave::boot_complete`] (and send its boot-up message).
    ResetNode,
    /// A reset-communication command arrived: the application must reset the
    /// communication parameters, then call [`NmtSlave::boot_complete`].
    ResetCommunication,
}

/// NMT slave state machine (CiA 301) of one node. It starts in
/// [`NmtState::BootUp`] (initialising) and reacts to commands addressed to
/// its node id or to all nodes; while initialising it ignores commands. It
/// sends nothing itself: the boot-up and heartbeat frames come from
/// [`crate::heartbeat::HeartbeatProducer`].
///
/// On a reset command the slave goes back to [`NmtState::BootUp`] and
/// reports the request (first the reset event, then the state change).
/// Its event queue holds 8 events; when full the oldest is dropped.
#[derive(Debug, Clone)]
pub struct NmtSlave {
    node: NodeId,
    state: NmtState,
    events: Ring<NmtSlaveEvent, 8>,
}

impl NmtSlave {
    /// The state machine of `node`, initialising.
    pub const fn new(node: NodeId) -> NmtSlave {
        NmtSlave {
            node,
            state: NmtState::BootUp,
            events: Ring::new(),
        }
    }

    /// The node id the slave answers to.
    pub const fn node(&self) -> NodeId {
        self.node
    }

    /// The current state.
    pub const fn state(&self) -> NmtState {
        self.state
    }

    /// Initialisation finished: enter Pre-operational (only from the
    /// initialising state; otherwise nothing happens).
    pub fn boot_complete(&mut self) {
        if self.state == NmtState::BootUp {
            self.set_state(NmtState::PreOperational);
        }
    }

    /// Carries `cmd` out as if it had been received (a local command).
    pub fn apply(&mut self, cmd: NmtCommand) {
        if self.state == NmtState::BootUp {
            return;
        }
        match cmd {
            NmtCommand::Start => self.set_state(NmtState::Operational),
            NmtCommand::Stop => self.set_state(NmtState::Stopped),
            NmtCommand::EnterPreOperational => self.set_state(NmtState::PreOperational),
            NmtCommand::ResetNode => {
                self.events.push(NmtSlaveEvent::ResetNode);
                self.set_state(NmtState::BootUp);
            }
            NmtCommand::ResetCommunication => {
                self.events.push(NmtSlaveEvent::ResetCommunication);
                self.set_state(NmtState::BootUp);
            }
        }
    }

    /// Events dropped because the event queue was full.
    pub fn dropped_events(&self) -> u32 {
        self.events.dropped()
    }

    fn set_state(&mut self, to: NmtState) {
        let from = self.state;
        if from != to {
            self.state = to;
            self.events.push(NmtSlaveEvent::StateChanged { from, to });
        }
    }
}

impl Service for NmtSlave {
    type Event = NmtSlaveEvent;

    fn handle_frame(&mut self, _now: Instant, frame: &Frame) {
        if let Some((cmd, target)) = parse_command(frame)
            && target.includes(self.node)
        {
            self.apply(cmd);
        }
    }

    fn poll_event(&mut self) -> Option<NmtSlaveEvent> {
        self.events.pop()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cores::testing::{data, events, node};

    #[test]
    fn slave_follows_commands() {
        let mut s = NmtSlave::new(node(32));
        let t = Instant::ZERO;
        // Ignored while initialising.
        s.handle_frame(t, &data(0x000, &[0x01, 0x20]));
        assert_eq!(s.state(), NmtState::BootUp);
        s.boot_complete();
        assert_eq!(
            events(&mut s),
            [NmtSlaveEvent::StateChanged {
                from: NmtState::BootUp,
                to: NmtState::PreOperational
            }]
        );
        // Addressed to another node: ignored.
        s.handle_frame(t, &data(0x000, &[0x01, 0x21]));
        assert_eq!(s.state(), NmtState::PreOperational);
        s.handle_frame(t, &data(0x000, &[0x01, 0x20]));
        assert_eq!(s.state(), NmtState::Operational);
        // Broadcast stop.
        s.handle_frame(t, &data(0x000, &[0x02, 0x00]));
        assert_eq!(s.state(), NmtState::Stopped);
        s.handle_frame(t, &data(0x000, &[0x02, 0x00]));
        assert_eq!(events(&mut s).len(), 2);
        s.handle_frame(t, &data(0x000, &[0x82, 0x20]));
        assert_eq!(
            events(&mut s),
            [
                NmtSlaveEvent::ResetCommunication,
                NmtSlaveEvent::StateChanged {
                    from: NmtState::Stopped,
                    to: NmtState::BootUp
                }
            ]
        );
        s.boot_complete();
        s.handle_frame(t, &data(0x000, &[0x81, 0x00]));
        assert_eq!(events(&mut s)[1], NmtSlaveEvent::ResetNode);
        assert_eq!(s.state(), NmtState::BootUp);
    }
}
