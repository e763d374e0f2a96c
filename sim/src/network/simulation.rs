//! The simulated slaves of a network as one sans-IO [`Service`]: frames
//! and time in, frames and [`Event`]s out. A frame one slave sends is
//! delivered to the others as well (they share the bus), then handed out.

use std::collections::VecDeque;

use eds2rust_runtime::nmt::NmtState;
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::{Frame, Instant, Service};

use super::node::{SimNode, Step};
use super::{FaultError, NodeFault};
use crate::cia402::Cia402Event;
use crate::{ObjectTable, SimEvent};

/// What a simulated network reports.
#[derive(Debug, Clone, PartialEq)]
pub enum Event {
    /// An event of a node's device (a generic device has no model events).
    Device(NodeId, SimEvent<Cia402Event>),
    /// A node was powered on (its boot-up message follows).
    PoweredOn(NodeId),
    /// A node lost power ([`super::Fault::PowerLoss`]).
    PoweredOff(NodeId),
    /// A node's heartbeat stopped ([`super::Fault::HeartbeatStops`]).
    HeartbeatStopped(NodeId),
    /// A node's heartbeat came back.
    HeartbeatResumed(NodeId),
}

/// Every simulated slave of a network, running (see the module
/// documentation); built by [`super::Network::simulation`].
#[derive(Debug)]
pub struct Simulation {
    pub(super) nodes: Vec<SimNode>,
    now: Instant,
    /// Where the transmit rotation goes on.
    next: usize,
    events: VecDeque<Event>,
}

impl Simulation {
    pub(super) fn new(nodes: Vec<SimNode>, start: Instant) -> Simulation {
        let mut sim = Simulation {
            nodes,
            now: start,
            next: 0,
            events: VecDeque::new(),
        };
        // Nodes powered at the start send their boot-up message at once.
        sim.run_steps(start);
        sim
    }

    /// The simulated nodes, by node id.
    pub fn nodes(&self) -> impl Iterator<Item = NodeId> + '_ {
        self.nodes.iter().map(|n| n.node)
    }

    /// The name of `node` in the bus file.
    pub fn name(&self, node: NodeId) -> Option<&str> {
        self.find(node).map(|n| n.name.as_str())
    }

    /// Whether `node` is powered (on the bus).
    pub fn is_powered(&self, node: NodeId) -> bool {
        self.find(node).is_some_and(|n| n.powered)
    }

    /// The NMT state of `node`, while it is powered.
    pub fn nmt_state(&self, node: NodeId) -> Option<NmtState> {
        let n = self.find(node).filter(|n| n.powered)?;
        n.model.as_ref().map(|m| m.nmt_state())
    }

    /// The object table of `node` (once it was powered on: what it holds
    /// now, what the master wrote included).
    pub fn table(&self, node: NodeId) -> Option<&ObjectTable> {
        self.find(node)?.model.as_ref().map(|m| m.table())
    }

    /// An unsigned entry of `node`'s table.
    pub fn get_uint(&self, node: NodeId, index: u16, sub: u8) -> Option<u64> {
        self.table(node)?.get_uint(index, sub)
    }

    /// Makes `fault` happen from `now` on, while the simulation runs (its
    /// times count from `now`): a power loss, an error control stop, a
    /// refused write, a late power-on of a node not yet powered, or
    /// `Missing` (off from now on, for good). Faults on what a device holds
    /// from power-on (identity, configuration) are given to
    /// [`super::Network::simulation`]; here they are an error.
    pub fn inject(&mut self, fault: NodeFault, now: Instant) -> Result<(), FaultError> {
        let node = self
            .nodes
            .iter_mut()
            .find(|n| n.node == fault.node)
            .ok_or_else(|| FaultError {
                fault,
                reason: format!("the simulation has no node {}", fault.node),
            })?;
        node.inject(now, fault.fault).map_err(|why| FaultError {
            fault,
            reason: why.to_string(),
        })?;
        // What is due now happens now.
        self.run_steps(now);
        Ok(())
    }

    fn find(&self, node: NodeId) -> Option<&SimNode> {
        self.nodes.iter().find(|n| n.node == node)
    }

    /// Applies the scheduled changes due at `now` (after the events so
    /// far, so that they stay in order).
    fn run_steps(&mut self, now: Instant) {
        if self
            .nodes
            .iter()
            .any(|n| n.next_step().is_some_and(|at| at <= now))
        {
            self.collect_events();
        }
        for node in &mut self.nodes {
            while let Some(step) = node.take_step(now) {
                node.apply(now, step);
                let id = node.node;
                self.events.push_back(match step {
                    Step::PowerOn => Event::PoweredOn(id),
                    Step::PowerOff => Event::PoweredOff(id),
                    Step::HeartbeatOff => Event::HeartbeatStopped(id),
                    Step::HeartbeatOn => Event::HeartbeatResumed(id),
                });
            }
        }
    }

    fn collect_events(&mut self) {
        for node in &mut self.nodes {
            while let Some(e) = node.poll_event() {
                self.events.push_back(Event::Device(node.node, e));
            }
        }
    }
}

impl Service for Simulation {
    type Event = Event;

    fn handle_frame(&mut self, now: Instant, frame: &Frame) {
        self.now = now;
        for node in &mut self.nodes {
            node.handle_frame(now, frame);
        }
    }

    fn handle_timeout(&mut self, now: Instant) {
        self.now = now;
        self.run_steps(now);
        for node in &mut self.nodes {
            node.handle_timeout(now);
        }
    }

    /// One frame of the next node that has one, in rotation; the other
    /// nodes receive it first, as on the bus.
    fn poll_transmit(&mut self) -> Option<Frame> {
        let count = self.nodes.len();
        for k in 0..count {
            let i = (self.next + k) % count;
            if let Some(frame) = self.nodes[i].poll_transmit() {
                self.next = (i + 1) % count;
                let now = self.now;
                for (j, other) in self.nodes.iter_mut().enumerate() {
                    if j != i {
                        other.handle_frame(now, &frame);
                    }
                }
                return Some(frame);
            }
        }
        None
    }

    fn poll_event(&mut self) -> Option<Event> {
        if self.events.is_empty() {
            self.collect_events();
        }
        self.events.pop_front()
    }

    fn poll_timeout(&self) -> Option<Instant> {
        self.nodes.iter().filter_map(SimNode::poll_timeout).min()
    }
}
