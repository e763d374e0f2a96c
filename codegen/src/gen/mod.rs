//! Generators: the IR ([`Device`]) → files.
//!
//! - `eds` (feature `export`): a CiA 306 EDS export (`eds::to_eds`, `eds::to_eds_variant`);
//! - [`rust`]: typed Rust for a device (zero-sized entry types, value types,
//!   PDO structs, error enums), formatted by prettyplease;
//! - [`apply_variant`]: the device as one of its product [`Variant`](crate::ir::Variant)s,
//!   for any generator.

#[cfg(feature = "export")]
pub mod eds;
pub mod rust;

#[cfg(feature = "export")]
pub use eds::{to_eds, to_eds_variant};

use core::fmt;

use crate::ir::{Device, Literal, Origin, Value};

/// Why [`apply_variant`] (and `to_eds_variant`) could not make a device
/// variant.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum VariantError {
    /// The device has no variant of this name; `known` are the names it has.
    Unknown { name: String, known: Vec<String> },
    /// An override of the variant names an entry the device does not have.
    MissingEntry {
        variant: String,
        index: u16,
        subindex: u8,
        /// Where the override is written.
        origin: Origin,
    },
}

impl fmt::Display for VariantError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            VariantError::Unknown { name, known } if known.is_empty() => {
                write!(
                    f,
                    "unknown variant `{name}`: the device defines no variants"
                )
            }
            VariantError::Unknown { name, known } => write!(
                f,
                "unknown variant `{name}`; the device defines: {}",
                known.join(", ")
            ),
            VariantError::MissingEntry {
                variant,
                index,
                subindex,
                origin,
            } => {
                if !origin.file.is_empty() {
                    write!(f, "{}:{}: ", origin.file, origin.line)?;
                }
                write!(
                    f,
                    "variant `{variant}` overrides 0x{index:04X} sub {subindex}, \
                     which the device does not have"
                )
            }
        }
    }
}

impl std::error::Error for VariantError {}

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
/// Errors: an unknown variant name ([`VariantError::Unknown`], with the
/// known ones), or an override that names an index/subindex the device does
/// not have ([`VariantError::MissingEntry`]).
pub fn apply_variant(device: &Device, name: &str) -> Result<Device, VariantError> {
    let Some(variant) = device.variants.iter().find(|v| v.name == name) else {
        return Err(VariantError::Unknown {
            name: name.into(),
            known: device.variants.iter().map(|v| v.name.clone()).collect(),
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
            return Err(VariantError::MissingEntry {
                variant: name.into(),
                index: o.index,
                subindex: o.subindex,
                origin: o.origin.clone(),
            });
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
            .insert(0, Box::new(Entry::highest_subindex(2, Origin::default())));
        identity
            .entries
            .insert(1, Box::new(var(0x1018, 1, "Vendor-ID")));
        identity
            .entries
            .insert(2, Box::new(var(0x1018, 2, "Product code")));
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
        assert_eq!(
            err.to_string(),
            "unknown variant `small`; the device defines: big"
        );
        let err = apply_variant(&Device::default(), "small").unwrap_err();
        assert_eq!(
            err.to_string(),
            "unknown variant `small`: the device defines no variants"
        );
        let mut d = device();
        d.variants[0].overrides[0].index = 0x2000;
        d.variants[0].overrides[0].origin = Origin {
            file: "big.yaml".into(),
            line: 12,
        };
        let err = apply_variant(&d, "big").unwrap_err();
        assert!(matches!(
            err,
            VariantError::MissingEntry {
                index: 0x2000,
                subindex: 1,
                ..
            }
        ));
        assert_eq!(
            err.to_string(),
            "big.yaml:12: variant `big` overrides 0x2000 sub 1, which the device does not have"
        );
    }
}
