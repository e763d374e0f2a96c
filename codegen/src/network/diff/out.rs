//! What the wiring rules share: the change pusher of one section, the
//! grading of values where 0 means off, and small value helpers.

use std::fmt::Display;

use super::{NetChange, NetKind, Wiring};
use crate::diff::{Severity, Val, hex};
use crate::network::config::Node;
use crate::network::model::{At, Bus, SlaveSection};
use crate::text::code_span;

/// Pushes the changes of one section (a node, `master`, `options`).
pub(super) struct Out<'a> {
    pub out: &'a mut Vec<NetChange>,
    pub node: &'a str,
}

impl Out<'_> {
    #[allow(clippy::too_many_arguments)]
    pub(super) fn push(
        &mut self,
        kind: Wiring,
        severity: Severity,
        (index, subindex): (u16, Option<u8>),
        place: &str,
        old: Option<Val>,
        new: Option<Val>,
        message: String,
    ) {
        self.out.push(NetChange {
            node: self.node.to_string(),
            kind: NetKind::Wiring(kind),
            severity,
            index,
            subindex,
            place: place.to_string(),
            rust_path: None,
            old,
            new,
            message,
        });
    }

    /// A value where 0 means off ([`graded`]), pushed when it changed.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn timed(
        &mut self,
        kind: Wiring,
        at: (u16, Option<u8>),
        place: &str,
        what: &str,
        unit: &str,
        old: u64,
        new: u64,
    ) {
        if old == new {
            return;
        }
        let message = match (old, new) {
            (0, n) => format!("{what} switched on: {n} {unit}"),
            (o, 0) => format!("{what} switched off: was {o} {unit}"),
            (o, n) => format!("{what} {o} → {n} {unit}"),
        };
        let (ov, nv) = (Val::Int(old.into()), Val::Int(new.into()));
        self.push(
            kind,
            graded(old, new),
            at,
            place,
            Some(ov),
            Some(nv),
            message,
        );
    }

    /// A boot setting compared as written: absent shows as `default`.
    pub(super) fn setting<T: PartialEq + Display>(
        &mut self,
        key: &str,
        old: Option<&T>,
        new: Option<&T>,
    ) {
        if old == new {
            return;
        }
        let val = |v: Option<&T>| v.map(|v| Val::Text(v.to_string()));
        let show = |v: Option<&T>| v.map_or("default".to_string(), |v| v.to_string());
        let message = format!("{} {} → {}", code_span(key), show(old), show(new));
        self.push(
            Wiring::SettingChanged,
            Severity::Compatible,
            (0, None),
            key,
            val(old),
            val(new),
            message,
        );
    }
}

/// A time or period where 0 means off: switched on is additive, switched
/// off breaking, changed compatible (call only when `old != new`).
pub(super) fn graded(old: u64, new: u64) -> Severity {
    match (old, new) {
        (0, _) => Severity::Additive,
        (_, 0) => Severity::Breaking,
        _ => Severity::Compatible,
    }
}

pub(super) fn at_value<T>(at: &Option<At<T>>) -> Option<&T> {
    at.as_ref().map(|a| &a.value)
}

/// `0x1A8` as text, for COB-IDs and identity numbers.
pub(super) fn hex_val(v: u32) -> Val {
    Val::Text(hex(v.into()))
}

/// How long a consumer waits for a heartbeat produced every `producer` ms
/// (dcfgen: the producer time times the multiplier, truncated to 16 bits).
pub(super) fn consumer_time(producer: u16, multiplier: f64) -> u64 {
    crate::network::config::heartbeat_product(producer, multiplier) & 0xFFFF
}

/// One side of a node pair: the bus, the configured node, its section.
pub(super) type Side<'a> = (&'a Bus, &'a Node, &'a SlaveSection);
