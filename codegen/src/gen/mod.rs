//! Generators: the IR ([`Device`]) → files.
//!
//! - [`eds`]: a CiA 306 EDS export ([`eds::to_eds`], [`eds::to_eds_variant`]);
//! - [`rust`]: typed Rust for a device (zero-sized entry types, value types,
//!   PDO structs, error enums), formatted by prettyplease;
//! - [`apply_variant`]: the device as one of its product [`Variant`](crate::ir::Variant)s,
//!   for any generator.

pub mod eds;
pub mod rust;

pub use eds::{to_eds, to_eds_variant};

use crate::ir::{Device, Literal, Value};

/// The device as its product variant `name`.
///
/// Applied: the variant's identity fields that are `Some` (into
/// [`Device::identity`], and into the defaults of object 0x1018 sub 1–3 —
/// vendor id, product code, revision — when those entries exist, so that the
/// two stay in agreement as a reader expects), then every override of
/// default / low limit / high limit (a `None` field of an override leaves the
/// entry's value as it is). Overrides come last, so an override of 0x1018
/// wins over the identity. Not carried: the variant's node id and bit rate
/// (network defaults, not dictionary content) and its description. The
/// result keeps the device's list of variants.
///
/// Errors: an unknown variant name (the message lists the known ones), or an
/// override that names an index/subindex the device does not have.
pub fn apply_variant(device: &Device, name: &str) -> Result<Device, String> {
    let Some(variant) = device.variants.iter().find(|v| v.name == name) else {
        let known: Vec<&str> = device.variants.iter().map(|v| v.name.as_str()).collect();
        return Err(if known.is_empty() {
            format!("unknown variant `{name}`: the device defines no variants")
        } else {
            format!(
                "unknown variant `{name}`; the device defines: {}",
                known.join(", ")
            )
        });
    };
    let mut out = device.clone();
    let id = &variant.identity;
    let identity = &mut out.identity;
    if id.vendor_name.is_some() {
        identity.vendor_name.clone_from(&id.vendor_name);
    }
    if id.product_name.is_some() {
        identity.product_name.clone_from(&id.product_name);
    }
    if id.order_code.is_some() {
        identity.order_code.clone_from(&id.order_code);
    }
    for (sub, number, field) in [
        (1u8, id.vendor_number, &mut identity.vendor_number),
        (2, id.product_number, &mut identity.product_number),
        (3, id.revision_number, &mut identity.revision_number),
    ] {
        let Some(number) = number else { continue };
        *field = Some(number);
        if let Some(entry) = out
            .objects
            .get_mut(&0x1018)
            .and_then(|o| o.entries.get_mut(&sub))
        {
            entry.default = Some(Literal {
                value: Value::Integer(number.into()),
                plus_node_id: false,
                text: format!("0x{number:08X}"),
            });
        }
    }
    for o in &variant.overrides {
        let Some(entry) = out
            .objects
            .get_mut(&o.index)
            .and_then(|obj| obj.entries.get_mut(&o.subindex))
        else {
            return Err(format!(
                "variant `{name}` overrides 0x{:04X} sub {}, which the device does not have",
                o.index, o.subindex
            ));
        };
        if o.default.is_some() {
            entry.default.clone_from(&o.default);
        }
        if o.low_limit.is_some() {
            entry.low_limit.clone_from(&o.low_limit);
        }
        if o.high_limit.is_some() {
            entry.high_limit.clone_from(&o.high_limit);
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ir::{
        Access, DataType, Entry, EntryOverride, Identity, Object, ObjectKind, Origin, Variant,
    };

    fn lit(v: i128) -> Literal {
        Literal {
            value: Value::Integer(v),
            plus_node_id: false,
            text: v.to_string(),
        }
    }

    fn device() -> Device {
        let var = |index: u16, sub: u8, name: &str| Entry {
            subindex: sub,
            name: name.into(),
            data_type: DataType::Unsigned32,
            access: Access::Ro,
            pdo_mappable: false,
            default: Some(lit(1)),
            low_limit: None,
            high_limit: None,
            parameter_value: None,
            obj_flags: None,
            denotation: None,
            semantics: Default::default(),
            rust_name: None,
            origin: Origin {
                file: format!("{index:x}"),
                line: 0,
            },
        };
        let mut d = Device::default();
        let mut identity = Object {
            index: 0x1018,
            name: "Identity object".into(),
            kind: ObjectKind::Record,
            entries: Default::default(),
            obj_flags: None,
            denotation: None,
            compact_sub_obj: None,
            rust_name: None,
            origin: Origin::default(),
        };
        identity
            .entries
            .insert(0, Entry::highest_subindex(2, Origin::default()));
        identity.entries.insert(1, var(0x1018, 1, "Vendor-ID"));
        identity.entries.insert(2, var(0x1018, 2, "Product code"));
        d.objects.insert(0x1018, identity);
        d.identity.product_number = Some(1);
        d.variants.push(Variant {
            name: "big".into(),
            description: None,
            identity: Identity {
                product_number: Some(0x42),
                product_name: Some("Big one".into()),
                ..Identity::default()
            },
            node_id: Some(9),
            bit_rate: None,
            overrides: vec![EntryOverride {
                index: 0x1018,
                subindex: 1,
                default: None,
                low_limit: Some(lit(0)),
                high_limit: None,
                origin: Origin::default(),
            }],
            origin: Origin::default(),
        });
        d
    }

    #[test]
    fn variant_identity_and_overrides() {
        let d = apply_variant(&device(), "big").unwrap();
        assert_eq!(d.identity.product_number, Some(0x42));
        assert_eq!(d.identity.product_name.as_deref(), Some("Big one"));
        let e = &d.objects[&0x1018].entries;
        assert_eq!(e[&2].default.as_ref().unwrap().value, Value::Integer(0x42));
        assert_eq!(e[&1].default.as_ref().unwrap().value, Value::Integer(1));
        assert_eq!(e[&1].low_limit.as_ref().unwrap().value, Value::Integer(0));
        assert_eq!(d.network.node_id, None);
    }

    #[test]
    fn variant_errors_name_the_problem() {
        let err = apply_variant(&device(), "small").unwrap_err();
        assert!(err.contains("small") && err.contains("big"), "{err}");
        let mut d = device();
        d.variants[0].overrides[0].index = 0x2000;
        let err = apply_variant(&d, "big").unwrap_err();
        assert!(err.contains("0x2000 sub 1"), "{err}");
    }
}
