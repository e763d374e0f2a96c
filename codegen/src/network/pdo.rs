//! The lists inside a slave section: `rpdo:`/`tpdo:` with their
//! `mapping:`, `sdo:` and `error_behavior:`. Unknown keys inside their
//! items are warnings (dcfgen ignores them), with the closest known key.

use std::collections::BTreeMap;

use crate::diag::rules::closest_of;
use crate::table::At;

use super::model::{At as Valued, CobIdSetting, MappingItem, PdoSection, SdoItem, Spot};
use super::values::{Ctx, Entry, at};
use super::yaml::{Node, Value};

/// The keys of a PDO section.
const PDO_KEYS: &[&str] = &[
    "enabled",
    "cob_id",
    "transmission",
    "inhibit_time",
    "event_timer",
    "event_deadline",
    "sync_start",
    "mapping",
];
const MAPPING_KEYS: &[&str] = &["index", "sub_index"];
const SDO_KEYS: &[&str] = &["index", "sub_index", "value"];

/// The most PDOs of one direction (CiA 301: 0x1400–0x15FF, 0x1800–0x19FF).
const MAX_PDO: i128 = 512;

/// `rpdo:` or `tpdo:`: PDO number → section.
pub(crate) fn pdos(ctx: &mut Ctx, entry: &Entry) -> BTreeMap<u16, PdoSection> {
    let mut out = BTreeMap::new();
    let Some(items) = ctx.entries(entry.value, &entry.path) else {
        return out;
    };
    for item in items {
        let Value::Int(number) = item.key_node.value else {
            ctx.error(
                "net::pdo-number",
                item.key_node.at,
                &item.path,
                format!(
                    "a PDO is named by its number (1..={MAX_PDO}), not {}",
                    item.key_node.value.kind()
                ),
            );
            if matches!(&item.key_node.value, Value::Str(s) if s.trim().parse::<u16>().is_ok()) {
                ctx.note(
                    "dcfgen looks the PDO up by number and does not find quoted text: write the \
                     number without quotes"
                        .into(),
                );
            }
            continue;
        };
        if !(1..=MAX_PDO).contains(&number) {
            ctx.error(
                "net::pdo-number",
                item.key_node.at,
                &item.path,
                format!("PDO {number} does not exist: PDOs are numbered 1..={MAX_PDO}"),
            );
            continue;
        }
        let Ok(number) = u16::try_from(number) else {
            continue;
        };
        if let Some(section) = pdo(ctx, &item) {
            out.insert(number, section);
        }
    }
    out
}

fn pdo(ctx: &mut Ctx, item: &Entry) -> Option<PdoSection> {
    let keys = ctx.entries(item.value, &item.path)?;
    let mut section = PdoSection {
        spot: item.spot(),
        enabled: Valued::new(true, item.spot()),
        cob_id: None,
        transmission: None,
        inhibit_time: None,
        event_timer: None,
        event_deadline: None,
        sync_start: None,
        mapping: None,
    };
    for e in keys {
        let (node, path) = (e.value, e.path.as_str());
        match e.key.as_str() {
            "enabled" => {
                if let Some(v) = ctx.truthy(node, path) {
                    section.enabled = at(v, &e);
                }
            }
            "cob_id" => section.cob_id = cob_id(ctx, &e).map(|v| at(v, &e)),
            "transmission" => section.transmission = ctx.unsigned(node, path).map(|v| at(v, &e)),
            "inhibit_time" => section.inhibit_time = ctx.unsigned(node, path).map(|v| at(v, &e)),
            "event_timer" => section.event_timer = ctx.unsigned(node, path).map(|v| at(v, &e)),
            "event_deadline" => {
                section.event_deadline = ctx.unsigned(node, path).map(|v| at(v, &e));
            }
            "sync_start" => section.sync_start = ctx.unsigned(node, path).map(|v| at(v, &e)),
            "mapping" => section.mapping = mapping(ctx, &e),
            _ => unknown_key(ctx, &e, PDO_KEYS, "a PDO"),
        }
    }
    Some(section)
}

/// `cob_id:`: `auto` or a number (bit 31: not valid).
fn cob_id(ctx: &mut Ctx, e: &Entry) -> Option<CobIdSetting> {
    if let Value::Str(s) = &e.value.value {
        if s == "auto" {
            return Some(CobIdSetting::Auto);
        }
        if super::values::python_int(s).is_none() {
            ctx.error(
                "net::bad-value",
                e.value.at,
                &e.path,
                format!("a COB-ID is a number or `auto`, not the text {s:?}"),
            );
            if s.trim().eq_ignore_ascii_case("auto") {
                ctx.note("dcfgen knows only `auto` in lower case".into());
            }
            return None;
        }
    }
    ctx.unsigned::<u32>(e.value, &e.path)
        .map(CobIdSetting::Value)
}

/// `mapping:`, a list of `{index, sub_index}`.
fn mapping(ctx: &mut Ctx, e: &Entry) -> Option<Vec<MappingItem>> {
    let items = list(ctx, e, "mapping: [] maps nothing")?;
    let mut out = Vec::with_capacity(items.len());
    for (n, node) in items.iter().enumerate() {
        let path = format!("{}[{n}]", e.path);
        let Some(keys) = item_keys(ctx, node, &path) else {
            continue;
        };
        let mut index = None;
        let mut sub_index = 0;
        for k in keys {
            match k.key.as_str() {
                "index" => index = ctx.unsigned::<u16>(k.value, &k.path),
                "sub_index" => sub_index = ctx.unsigned(k.value, &k.path).unwrap_or(0),
                _ => unknown_key(ctx, &k, MAPPING_KEYS, "a mapping item"),
            }
        }
        match index {
            Some(index) => out.push(MappingItem {
                spot: Spot {
                    line: node.at.line,
                    key: path,
                },
                index,
                sub_index,
            }),
            None if !has_key(node, "index") => missing_index(ctx, node.at, &path),
            None => {}
        }
    }
    Some(out)
}

/// `sdo:`, a list of `{index, sub_index, value}`.
pub(crate) fn sdo(ctx: &mut Ctx, e: &Entry) -> Vec<SdoItem> {
    let Some(items) = list(ctx, e, "sdo: [] writes nothing") else {
        return Vec::new();
    };
    let mut out = Vec::with_capacity(items.len());
    for (n, node) in items.iter().enumerate() {
        let path = format!("{}[{n}]", e.path);
        let Some(keys) = item_keys(ctx, node, &path) else {
            continue;
        };
        let (mut index, mut sub_index, mut value) = (None, Some(0), Some(0));
        for k in keys {
            match k.key.as_str() {
                "index" => index = ctx.unsigned::<u16>(k.value, &k.path),
                "sub_index" => sub_index = ctx.unsigned(k.value, &k.path),
                "value" => value = ctx.integer(k.value, &k.path),
                _ => unknown_key(ctx, &k, SDO_KEYS, "an sdo item"),
            }
        }
        if !has_key(node, "index") {
            missing_index(ctx, node.at, &path);
        }
        if let (Some(index), Some(sub_index), Some(value)) = (index, sub_index, value) {
            out.push(SdoItem {
                spot: Spot {
                    line: node.at.line,
                    key: path,
                },
                index,
                sub_index,
                value,
            });
        }
    }
    out
}

/// `error_behavior:`, sub-index → value (dcfgen reads both with `int()`).
pub(crate) fn error_behavior(ctx: &mut Ctx, e: &Entry) -> BTreeMap<u8, Valued<u8>> {
    let mut out = BTreeMap::new();
    for k in ctx.entries(e.value, &e.path).unwrap_or_default() {
        let sub = ctx.unsigned::<u8>(k.key_node, &k.path);
        let value = ctx.unsigned::<u8>(k.value, &k.path);
        if let (Some(sub), Some(value)) = (sub, value) {
            out.insert(sub, at(value, &k));
        }
    }
    out
}

/// The items of a list key (`mapping:`, `sdo:`).
fn list<'n>(ctx: &mut Ctx, e: &Entry<'n>, empty_hint: &str) -> Option<&'n [Node]> {
    match &e.value.value {
        Value::Seq(items) => Some(items),
        other => {
            ctx.error(
                "net::bad-value",
                e.value.at,
                &e.path,
                format!("a list is needed here, not {}", other.kind()),
            );
            if matches!(other, Value::Null) {
                ctx.note(format!(
                    "dcfgen fails on an empty value; write `{empty_hint}`"
                ));
            }
            None
        }
    }
}

/// The keys of a list item, which must be a map.
fn item_keys<'n>(ctx: &mut Ctx, node: &'n Node, path: &str) -> Option<Vec<Entry<'n>>> {
    if !matches!(node.value, Value::Map(_)) {
        ctx.error(
            "net::bad-value",
            node.at,
            path,
            format!(
                "an item here is a map such as {{index: 0x6041, sub_index: 0}}, not {}",
                node.value.kind()
            ),
        );
        return None;
    }
    ctx.entries(node, path)
}

fn has_key(node: &Node, key: &str) -> bool {
    match &node.value {
        Value::Map(pairs) => pairs.iter().any(|(k, _)| k.value == Value::Str(key.into())),
        _ => false,
    }
}

fn missing_index(ctx: &mut Ctx, at: At, path: &str) {
    ctx.error(
        "net::missing-key",
        at,
        path,
        "the item has no `index`, which dcfgen needs".into(),
    );
}

/// A key that dcfgen ignores inside an item: a warning, with the closest
/// known key.
fn unknown_key(ctx: &mut Ctx, e: &Entry, known: &[&str], what: &str) {
    ctx.warn(
        "net::unknown-key",
        e.key_node.at,
        &e.path,
        format!("unknown key in {what}; dcfgen ignores it"),
    );
    match closest_of(&e.key, known.iter().copied()) {
        Some(close) => ctx.note(format!("did you mean `{close}`?")),
        None => ctx.note(format!("the keys here are {}", known.join(", "))),
    }
}
