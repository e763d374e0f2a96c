//! One simulated slave of a network: its device (generic, or the generic
//! CiA 402 drive), its power and its faults over time.

use std::time::Duration;

use eds2rust_runtime::nmt::NmtState;
use eds2rust_runtime::od::{AccessRight, DataType, DefaultValue, NodeId, Number, ObjectInfo};
use eds2rust_runtime::sdo::abort::AbortCode;
use eds2rust_runtime::{CanId, Frame, Instant, Service};

use super::fault::Fault;
use crate::behaviour::{Behaviour, Context};
use crate::cia402::{Cia402, Cia402Event};
use crate::{Device, DeviceConfig, ObjectTable, SimEvent};

/// A behaviour with the writes a fault refuses ([`Fault::SdoAbort`]).
#[derive(Debug)]
pub(super) struct Refusing<B> {
    inner: B,
    refused: Vec<(u16, u8, AbortCode)>,
}

impl<B: Behaviour> Behaviour for Refusing<B> {
    type Event = B::Event;

    fn check_write(
        &mut self,
        ctx: &mut Context<'_, Self::Event>,
        index: u16,
        sub: u8,
        data: &[u8],
    ) -> Result<(), AbortCode> {
        if let Some((_, _, code)) = self
            .refused
            .iter()
            .find(|(i, s, _)| (*i, *s) == (index, sub))
        {
            return Err(*code);
        }
        self.inner.check_write(ctx, index, sub, data)
    }
    fn written(&mut self, ctx: &mut Context<'_, Self::Event>, index: u16, sub: u8) {
        self.inner.written(ctx, index, sub);
    }
    fn step(&mut self, ctx: &mut Context<'_, Self::Event>) {
        self.inner.step(ctx);
    }
    fn period(&self) -> Duration {
        self.inner.period()
    }
    fn nmt_changed(&mut self, ctx: &mut Context<'_, Self::Event>, from: NmtState, to: NmtState) {
        self.inner.nmt_changed(ctx, from, to);
    }
    fn heartbeat_lost(&mut self, ctx: &mut Context<'_, Self::Event>, node: NodeId) {
        self.inner.heartbeat_lost(ctx, node);
    }
    fn heartbeat_resumed(&mut self, ctx: &mut Context<'_, Self::Event>, node: NodeId) {
        self.inner.heartbeat_resumed(ctx, node);
    }
    fn sync(&mut self, ctx: &mut Context<'_, Self::Event>) {
        self.inner.sync(ctx);
    }
    fn reset_application(&mut self, ctx: &mut Context<'_, Self::Event>) {
        self.inner.reset_application(ctx);
    }
}

/// The device of a node: a generic one or a CiA 402 drive.
#[derive(Debug)]
pub(super) enum Model {
    Plain(Box<Device<Refusing<()>>>),
    Drive(Box<Device<Refusing<Cia402>>>),
}

macro_rules! each {
    ($model:expr, $d:ident => $body:expr) => {
        match $model {
            Model::Plain($d) => $body,
            Model::Drive($d) => $body,
        }
    };
}

impl Model {
    pub(super) fn table(&self) -> &ObjectTable {
        each!(self, d => d.table())
    }

    pub(super) fn nmt_state(&self) -> NmtState {
        each!(self, d => d.nmt_state())
    }

    fn power_cycle(&mut self, now: Instant) {
        match self {
            Model::Plain(d) => d.power_cycle(now),
            // The drive model starts again in its reset_application.
            Model::Drive(d) => d.power_cycle(now),
        }
    }

    fn poll_event(&mut self) -> Option<SimEvent<Cia402Event>> {
        match self {
            Model::Plain(d) => d.poll_event().map(widen),
            Model::Drive(d) => d.poll_event(),
        }
    }
}

/// A generic device's event as a network's (it has no model events).
fn widen(event: SimEvent<std::convert::Infallible>) -> SimEvent<Cia402Event> {
    match event {
        SimEvent::Nmt { from, to } => SimEvent::Nmt { from, to },
        SimEvent::Written { index, sub } => SimEvent::Written { index, sub },
        SimEvent::Sdo(e) => SimEvent::Sdo(e),
        SimEvent::HeartbeatLost(n) => SimEvent::HeartbeatLost(n),
        SimEvent::HeartbeatResumed(n) => SimEvent::HeartbeatResumed(n),
        SimEvent::Emcy(code) => SimEvent::Emcy(code),
        SimEvent::LssNodeId(n) => SimEvent::LssNodeId(n),
        SimEvent::LssStored(n) => SimEvent::LssStored(n),
        SimEvent::ModelError(e) => SimEvent::ModelError(e),
        SimEvent::Model(never) => match never {},
    }
}

/// What happens to a node at a time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Step {
    PowerOn,
    PowerOff,
    HeartbeatOff,
    HeartbeatOn,
}

/// One simulated slave.
#[derive(Debug)]
pub(super) struct SimNode {
    pub(super) name: String,
    pub(super) node: NodeId,
    objects: &'static [ObjectInfo],
    drive: bool,
    time_scale: f64,
    refused: Vec<(u16, u8, AbortCode)>,
    /// Values the device holds saved (0x1010) from its first power-on.
    stored: Vec<(u16, u8, Vec<u8>)>,
    pub(super) model: Option<Model>,
    pub(super) powered: bool,
    pub(super) heartbeat_off: bool,
    /// What happens when, in time order.
    schedule: Vec<(Instant, Step)>,
}

impl SimNode {
    /// A node of `objects` (with the identity and 0x1020 values of its
    /// faults already in) whose faults are `faults`, the simulation
    /// starting at `start`.
    pub(super) fn new(
        name: String,
        node: NodeId,
        objects: &'static [ObjectInfo],
        drive: bool,
        faults: &[Fault],
        start: Instant,
    ) -> SimNode {
        let mut schedule = Vec::new();
        let mut refused = Vec::new();
        let mut power_on = Some(start);
        for fault in faults {
            match *fault {
                Fault::Missing => power_on = None,
                Fault::LateBoot(d) => power_on = power_on.map(|_| start + d),
                Fault::PowerLoss { at, off } => {
                    schedule.push((start + at, Step::PowerOff));
                    schedule.push((start + at + off, Step::PowerOn));
                }
                Fault::HeartbeatStops { at, resume } => {
                    schedule.push((start + at, Step::HeartbeatOff));
                    if let Some(r) = resume {
                        schedule.push((start + at + r, Step::HeartbeatOn));
                    }
                }
                Fault::SdoAbort { index, sub, code } => refused.push((index, sub, code)),
                Fault::Identity(..)
                | Fault::ConfigurationCurrent
                | Fault::ConfigurationDate { .. } => {}
            }
        }
        if faults.contains(&Fault::Missing) {
            // Never on the bus: nothing else happens to it.
            schedule.clear();
        }
        if let Some(at) = power_on {
            schedule.push((at, Step::PowerOn));
        }
        // Stable: a power-on at the instant of a loss comes after it.
        schedule.sort_by_key(|(at, _)| *at);
        SimNode {
            name,
            node,
            objects,
            drive,
            time_scale: 1.0,
            refused,
            stored: Vec::new(),
            model: None,
            powered: false,
            heartbeat_off: false,
            schedule,
        }
    }

    /// Applies `fault` from `now` on (times count from `now`): power loss,
    /// error control stop, a refused write, a late power-on of a node not
    /// yet powered, or `Missing` (off for good). The others change what
    /// the device holds from power-on: an error.
    pub(super) fn inject(&mut self, now: Instant, fault: Fault) -> Result<(), &'static str> {
        match fault {
            Fault::Missing => {
                self.schedule.clear();
                self.schedule.push((now, Step::PowerOff));
            }
            Fault::LateBoot(d) => {
                if self.powered || self.model.is_some() {
                    return Err("the node was powered on already");
                }
                self.schedule.retain(|(_, s)| *s != Step::PowerOn);
                self.schedule.push((now + d, Step::PowerOn));
            }
            Fault::PowerLoss { at, off } => {
                self.schedule.push((now + at, Step::PowerOff));
                self.schedule.push((now + at + off, Step::PowerOn));
            }
            Fault::HeartbeatStops { at, resume } => {
                self.schedule.push((now + at, Step::HeartbeatOff));
                if let Some(r) = resume {
                    self.schedule.push((now + at + r, Step::HeartbeatOn));
                }
            }
            Fault::SdoAbort { index, sub, code } => {
                self.refused.push((index, sub, code));
                if let Some(model) = self.model.as_mut() {
                    each!(model, d => d.with_model(now, |b, _| b.refused.push((index, sub, code))));
                }
            }
            Fault::Identity(..) | Fault::ConfigurationCurrent | Fault::ConfigurationDate { .. } => {
                return Err(
                    "it changes what the device holds from its power-on: give it to \
                            `Network::simulation`",
                );
            }
        }
        self.schedule.sort_by_key(|(at, _)| *at);
        Ok(())
    }

    /// Has the device hold `values` saved (0x1010) from its first
    /// power-on, as a device that was configured and stored before.
    pub(super) fn set_stored(&mut self, values: Vec<(u16, u8, Vec<u8>)>) {
        self.stored = values;
    }

    pub(super) fn set_time_scale(&mut self, factor: f64) {
        self.time_scale = factor;
    }

    /// The next scheduled change.
    pub(super) fn next_step(&self) -> Option<Instant> {
        self.schedule.first().map(|(at, _)| *at)
    }

    /// Takes the scheduled change due at `now`, if any.
    pub(super) fn take_step(&mut self, now: Instant) -> Option<Step> {
        if self.schedule.first().is_some_and(|(at, _)| *at <= now) {
            return Some(self.schedule.remove(0).1);
        }
        None
    }

    /// Applies `step` at `now`.
    pub(super) fn apply(&mut self, now: Instant, step: Step) {
        match step {
            Step::PowerOn => {
                match self.model.as_mut() {
                    Some(model) => model.power_cycle(now),
                    None => self.model = Some(self.power_on(now)),
                }
                self.powered = true;
            }
            Step::PowerOff => self.powered = false,
            Step::HeartbeatOff => self.heartbeat_off = true,
            Step::HeartbeatOn => self.heartbeat_off = false,
        }
    }

    fn power_on(&self, now: Instant) -> Model {
        let config = DeviceConfig::node(self.node);
        let refused = self.refused.clone();
        let mut model = if self.drive {
            let inner = Cia402::new().with_time_scale(self.time_scale);
            let model = Refusing { inner, refused };
            let mut device = Device::new(self.objects, config, model, now);
            // As `cia402::simulator` powers the drive on: its
            // reset_application is its power-on.
            device.with_model(now, |model, ctx| model.reset_application(ctx));
            Model::Drive(Box::new(device))
        } else {
            Model::Plain(Box::new(Device::new(
                self.objects,
                config,
                Refusing { inner: (), refused },
                now,
            )))
        };
        if !self.stored.is_empty() {
            // Configured and saved before: the values go in and are saved,
            // then the device is powered on with them (the first boot-up,
            // from the defaults, is not on the bus).
            each!(&mut model, d => {
                d.with_model(now, |_, ctx| {
                    for (index, sub, data) in &self.stored {
                        // An entry the table refuses keeps its default.
                        let _ = ctx.table_mut().set_raw(*index, *sub, data);
                    }
                });
                d.save();
                while d.poll_transmit().is_some() {}
                while d.poll_event().is_some() {}
            });
            model.power_cycle(now);
        }
        model
    }

    /// The powered device.
    pub(super) fn live(&mut self) -> Option<&mut Model> {
        if self.powered {
            self.model.as_mut()
        } else {
            None
        }
    }

    pub(super) fn handle_frame(&mut self, now: Instant, frame: &Frame) {
        if let Some(model) = self.live() {
            each!(model, d => d.handle_frame(now, frame));
        }
    }

    pub(super) fn poll_timeout(&self) -> Option<Instant> {
        let device = match (&self.model, self.powered) {
            (Some(model), true) => each!(model, d => d.poll_timeout()),
            _ => None,
        };
        [device, self.next_step()].into_iter().flatten().min()
    }

    pub(super) fn handle_timeout(&mut self, now: Instant) {
        if let Some(model) = self.live() {
            let due = each!(&*model, d => d.poll_timeout()).is_some_and(|t| t <= now);
            if due {
                each!(model, d => d.handle_timeout(now));
            }
        }
    }

    /// The next frame the node sends; heartbeats and guarding replies are
    /// dropped while its error control is stopped (the boot-up message
    /// still goes).
    pub(super) fn poll_transmit(&mut self) -> Option<Frame> {
        let heartbeat = CanId::Standard(0x700 + u16::from(self.node.get()));
        let off = self.heartbeat_off;
        let model = self.live()?;
        loop {
            let frame = each!(model, d => d.poll_transmit())?;
            let is_heartbeat = frame.id() == heartbeat && !frame.is_remote() && frame.data() != [0];
            if !(off && is_heartbeat) {
                return Some(frame);
            }
        }
    }

    pub(super) fn poll_event(&mut self) -> Option<SimEvent<Cia402Event>> {
        self.model.as_mut()?.poll_event()
    }
}

/// `objects` with the entries (index, sub) set to `value` as their
/// default (added as a read-only UNSIGNED32 when the table lacks them):
/// what identity and configuration-date faults change. Leaked as
/// [`crate::file`] leaks its tables.
pub(super) fn with_values(
    objects: &'static [ObjectInfo],
    values: &[((u16, u8), u32)],
) -> &'static [ObjectInfo] {
    if values.is_empty() {
        return objects;
    }
    let mut out = objects.to_vec();
    for &((index, sub), value) in values {
        let default = DefaultValue::Number(Number::Int(i128::from(value)));
        match out
            .iter_mut()
            .find(|o| (o.index, o.subindex) == (index, sub))
        {
            Some(entry) => entry.default = Some(default),
            None => out.push(
                ObjectInfo::new(
                    index,
                    sub,
                    "Simulated fault",
                    DataType::Unsigned32,
                    AccessRight::Ro,
                    false,
                )
                .with_default(default),
            ),
        }
    }
    out.sort_by_key(|o| (o.index, o.subindex));
    Box::leak(out.into_boxed_slice())
}
