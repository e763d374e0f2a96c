//! Device-level parts of a table: network defaults and LSS facts, error
//! tables, variants.

use std::collections::BTreeMap;

use serde_saphyr::Spanned;

use super::entry::literal;
use super::item::{entry_reference, find_entry};
use super::schema::{DeviceDef, ErrorTableDef, NetworkDef, VariantDef};
use super::{At, Ctx};
use crate::ir::{
    Device, EntryOverride, ErrorCode, ErrorTable, ErrorTableKind, Identity, Lss, Variant,
};

/// Bit rates of CiA 301's table, kbit/s (100 kbit/s is reserved there but
/// some devices use it).
const KNOWN_BIT_RATES: &[u32] = &[10, 20, 50, 100, 125, 250, 500, 800, 1000];

pub(super) fn network(ctx: &mut Ctx, device: &mut Device, def: &Spanned<NetworkDef>) {
    let n = &def.value;
    if let Some(node_id) = &n.node_id {
        check_node_id(ctx, node_id, "network", "node_id");
        device.network.node_id = Some(node_id.value);
    }
    for rate in n.bit_rate.iter().chain(&n.bit_rates) {
        if !KNOWN_BIT_RATES.contains(&rate.value) {
            ctx.error(
                "table::bit-rate",
                At::of(rate),
                "network",
                "bit_rate",
                format!(
                    "{} kbit/s is not a CANopen bit rate ({KNOWN_BIT_RATES:?})",
                    rate.value
                ),
            );
        }
    }
    if let Some(rate) = &n.bit_rate {
        device.network.bit_rate = Some(rate.value);
        if !n.bit_rates.is_empty() && !n.bit_rates.iter().any(|r| r.value == rate.value) {
            ctx.error(
                "table::bit-rate",
                At::of(rate),
                "network",
                "bit_rate",
                format!(
                    "the default bit rate {} kbit/s is not among `bit_rates`",
                    rate.value
                ),
            );
        }
    }
    if !n.bit_rates.is_empty() {
        let mut rates: Vec<u32> = n.bit_rates.iter().map(|r| r.value).collect();
        rates.sort_unstable();
        rates.dedup();
        device.capabilities.baud_rates = rates;
    }
    if let Some(auto) = n.auto_bit_rate {
        device.network.auto_bit_rate = auto;
    }
    if let Some(lss) = &n.lss {
        let l = &lss.value;
        let mut services: Vec<_> = l.services.iter().map(|s| s.value).collect();
        services.sort_unstable();
        services.dedup();
        if let Some(id) = &l.unconfigured_node_id {
            check_node_id(ctx, id, "network.lss", "unconfigured_node_id");
        }
        let mut bit_timing = Vec::new();
        let mut seen = BTreeMap::new();
        for row in &l.bit_timing {
            let r = &row.value;
            if let Some(first) = seen.insert(r.index.value, At::of(row).line) {
                ctx.error(
                    "table::duplicate-index",
                    At::of(&r.index),
                    "network.lss",
                    "bit_timing",
                    format!(
                        "bit timing index {} is already given at line {first}",
                        r.index.value
                    ),
                );
            }
            bit_timing.push((r.index.value, r.bit_rate.value));
        }
        bit_timing.sort_unstable();
        device.network.lss = Some(Lss {
            services,
            unconfigured_node_id: l.unconfigured_node_id.as_ref().map(|i| i.value),
            bit_timing,
        });
        device.capabilities.lss_supported = Some(true);
    }
}

fn check_node_id(ctx: &mut Ctx, id: &Spanned<u8>, place: &str, key: &str) {
    if !(1..=127).contains(&id.value) {
        ctx.error(
            "table::node-id",
            At::of(id),
            place,
            key,
            format!("node ids run from 1 to 127, not {}", id.value),
        );
    }
}

pub(super) fn error_tables(ctx: &mut Ctx, device: &mut Device, defs: &[Spanned<ErrorTableDef>]) {
    let mut names: BTreeMap<String, u32> = BTreeMap::new();
    for def in defs {
        let d = &def.value;
        let here = format!("errors {}", d.name.value);
        if let Some(first) = names.insert(d.name.value.clone(), At::of(def).line) {
            ctx.error(
                "table::duplicate-name",
                At::of(&d.name),
                &here,
                "name",
                format!(
                    "an error table `{}` is already defined at line {first}",
                    d.name.value
                ),
            );
            continue;
        }
        let limit = match d.kind.value {
            ErrorTableKind::Emcy => u32::from(u16::MAX),
            ErrorTableKind::Device | ErrorTableKind::SdoAbort => u32::MAX,
        };
        let mut seen: BTreeMap<u32, u32> = BTreeMap::new();
        let mut codes = Vec::new();
        for item in &d.codes {
            let c = &item.value;
            let at = At::of(item);
            if c.code.value > limit {
                ctx.error(
                    "table::value-out-of-range",
                    At::of(&c.code),
                    &here,
                    "code",
                    format!("0x{:X} does not fit a 16-bit EMCY error code", c.code.value),
                );
                continue;
            }
            if let Some(first) = seen.insert(c.code.value, at.line) {
                ctx.error(
                    "table::duplicate-code",
                    At::of(&c.code),
                    &here,
                    "code",
                    format!(
                        "code 0x{:X} is already listed at line {first}",
                        c.code.value
                    ),
                );
                continue;
            }
            let text = |t: &Option<Spanned<String>>| t.as_ref().map(|t| t.value.clone());
            codes.push(ErrorCode {
                code: c.code.value,
                name: c.name.value.clone(),
                text: text(&c.text),
                reaction: text(&c.reaction),
                configurable: c.configurable,
                remedy: text(&c.remedy),
                origin: ctx.origin(at),
            });
        }
        codes.sort_by_key(|c| c.code);
        device.error_tables.push(ErrorTable {
            name: d.name.value.clone(),
            kind: d.kind.value,
            description: d.description.as_ref().map(|t| t.value.clone()),
            codes,
            origin: ctx.origin(At::of(def)),
        });
    }
    device.error_tables.sort_by(|a, b| a.name.cmp(&b.name));
}

pub(super) fn variants(ctx: &mut Ctx, device: &mut Device, defs: &[Spanned<VariantDef>]) {
    let mut names: BTreeMap<String, u32> = BTreeMap::new();
    for def in defs {
        let d = &def.value;
        let here = format!("variant {}", d.name.value);
        if let Some(first) = names.insert(d.name.value.clone(), At::of(def).line) {
            ctx.error(
                "table::duplicate-name",
                At::of(&d.name),
                &here,
                "name",
                format!(
                    "a variant `{}` is already defined at line {first}",
                    d.name.value
                ),
            );
            continue;
        }
        let mut identity = Identity::default();
        if let Some(dev) = &d.device {
            apply_identity(ctx, &mut identity, dev, false);
        }
        if let Some(id) = &d.node_id {
            check_node_id(ctx, id, &here, "node_id");
        }
        let mut overrides: Vec<EntryOverride> = Vec::new();
        for item in &d.values {
            let Some((index, sub, entry_place)) = entry_reference(
                ctx,
                item,
                "a variant value",
                &[&["index", "sub", "default", "min", "max"]],
                "in a variant's `values` (only default, min and max differ between variants)",
            ) else {
                continue;
            };
            if overrides
                .iter()
                .any(|o| o.index == index && o.subindex == sub)
            {
                ctx.error(
                    "table::duplicate-index",
                    At::of(item),
                    &entry_place,
                    "index",
                    format!("{here} already changes {entry_place}"),
                );
                continue;
            }
            let Some(entry) = find_entry(ctx, device, index, sub, At::of(item)) else {
                continue;
            };
            let data_type = entry.data_type;
            let mut value = |key: &str, t: &Option<Spanned<String>>| {
                t.as_ref()
                    .and_then(|t| literal(ctx, &t.value, At::of(t), data_type, &entry_place, key))
            };
            let o = EntryOverride {
                index,
                subindex: sub,
                default: value("default", &item.value.default),
                low_limit: value("min", &item.value.min),
                high_limit: value("max", &item.value.max),
                origin: ctx.origin(At::of(item)),
            };
            overrides.push(o);
        }
        overrides.sort_by_key(|o| (o.index, o.subindex));
        device.variants.push(Variant {
            name: d.name.value.clone(),
            description: d.description.as_ref().map(|t| t.value.clone()),
            identity,
            node_id: d.node_id.as_ref().map(|n| n.value),
            bit_rate: d.bit_rate.as_ref().map(|n| n.value),
            overrides,
            origin: ctx.origin(At::of(def)),
        });
    }
}

/// Writes the identity fields a [`DeviceDef`] gives into `identity`.
/// `whole` also accepts `description` (a variant's goes elsewhere).
pub(super) fn apply_identity(
    ctx: &mut Ctx,
    identity: &mut Identity,
    def: &Spanned<DeviceDef>,
    whole: bool,
) {
    let d = &def.value;
    let text = |t: &Option<Spanned<String>>| t.as_ref().map(|t| t.value.clone());
    if let Some(v) = text(&d.vendor_name) {
        identity.vendor_name = Some(v);
    }
    if let Some(v) = &d.vendor_number {
        identity.vendor_number = Some(v.value);
    }
    if let Some(v) = text(&d.product_name) {
        identity.product_name = Some(v);
    }
    if let Some(v) = &d.product_number {
        identity.product_number = Some(v.value);
    }
    if let Some(v) = &d.revision_number {
        identity.revision_number = Some(v.value);
    }
    if let Some(v) = text(&d.order_code) {
        identity.order_code = Some(v);
    }
    if !whole && let Some(description) = &d.description {
        ctx.error(
            "table::misplaced-key",
            At::of(description),
            "variant device",
            "description",
            "a variant's description is `description:` of the variant itself".into(),
        );
    }
}
