//! The simulated device as a sans-IO [`Service`]: frames and timeouts in,
//! frames and [`SimEvent`]s out.

use eds2rust_runtime::heartbeat::HeartbeatEvent;
use eds2rust_runtime::nmt::{NmtState, NmtTarget, parse_command};
use eds2rust_runtime::sync::parse_sync_on;
use eds2rust_runtime::{Frame, Instant, Service};

use super::{Device, SimEvent};
use crate::behaviour::Behaviour;

impl<B: Behaviour> Service for Device<B> {
    type Event = SimEvent<B::Event>;

    fn handle_frame(&mut self, now: Instant, frame: &Frame) {
        self.server.store_mut().now = now;
        self.handle_lss(now, frame);
        if let Some((cmd, target)) = parse_command(frame) {
            let me = self.node();
            if target == NmtTarget::All || me.is_some_and(|me| target.includes(me)) {
                self.handle_nmt(now, cmd);
            }
            return;
        }
        if self.node().is_none() || self.nmt_state() == NmtState::BootUp {
            return;
        }
        self.consumer.handle_frame(now, frame);
        if let Some(guard) = self.guard.as_mut() {
            guard.handle_frame(now, frame);
        }
        let nmt = self.nmt_state();
        if nmt != NmtState::Stopped {
            if parse_sync_on(self.sync_cob_id(), frame).is_some() {
                if nmt == NmtState::Operational {
                    self.handle_sync(now, frame);
                }
                return;
            }
            if nmt == NmtState::Operational && self.receive_pdo(now, frame) {
                self.after_input(now);
                return;
            }
            self.server.handle_frame(now, frame);
        }
        self.after_input(now);
    }

    fn handle_timeout(&mut self, now: Instant) {
        self.server.store_mut().now = now;
        if let Some(hb) = self.heartbeat.as_mut()
            && hb.poll_timeout().is_some_and(|t| t <= now)
        {
            hb.handle_timeout(now);
        }
        if self.consumer.poll_timeout().is_some_and(|t| t <= now) {
            self.consumer.handle_timeout(now);
        }
        if self.server.poll_timeout().is_some_and(|t| t <= now) {
            self.server.handle_timeout(now);
        }
        for tpdo in &mut self.tpdos {
            if tpdo.tx.poll_timeout().is_some_and(|t| t <= now) {
                tpdo.tx.handle_timeout(now);
            }
        }
        if self.next_step <= now {
            self.run_step(now);
        }
    }

    fn poll_transmit(&mut self) -> Option<Frame> {
        if let Some(hb) = self.heartbeat.as_mut()
            && let Some(f) = hb.poll_transmit()
        {
            return Some(f);
        }
        if let Some(f) = self.guard.as_mut().and_then(Service::poll_transmit) {
            return Some(f);
        }
        if let Some(f) = self.outbox.pop_front() {
            return Some(f);
        }
        if let Some(f) = self.server.poll_transmit() {
            return Some(f);
        }
        self.tpdos.iter_mut().find_map(|t| t.tx.poll_transmit())
    }

    fn poll_event(&mut self) -> Option<SimEvent<B::Event>> {
        while let Some(e) = self.server.poll_event() {
            self.events.push_back(SimEvent::Sdo(e));
        }
        while let Some(e) = self.consumer.poll_event() {
            let now = self.server.store().now;
            match e {
                HeartbeatEvent::Timeout { node } => {
                    self.events.push_back(SimEvent::HeartbeatLost(node));
                    self.server
                        .store_mut()
                        .with_model(|b, ctx| b.heartbeat_lost(ctx, node));
                    self.after_input(now);
                }
                HeartbeatEvent::Resumed { node, .. } => {
                    self.events.push_back(SimEvent::HeartbeatResumed(node));
                    self.server
                        .store_mut()
                        .with_model(|b, ctx| b.heartbeat_resumed(ctx, node));
                    self.after_input(now);
                }
                _ => {}
            }
        }
        self.events.pop_front()
    }

    fn poll_timeout(&self) -> Option<Instant> {
        let mut at = Some(self.next_step);
        let mut take = |t: Option<Instant>| {
            if let Some(t) = t {
                at = Some(at.map_or(t, |a| a.min(t)));
            }
        };
        take(self.heartbeat.as_ref().and_then(Service::poll_timeout));
        take(self.consumer.poll_timeout());
        take(self.server.poll_timeout());
        for tpdo in &self.tpdos {
            take(tpdo.tx.poll_timeout());
        }
        at
    }
}
