//! The layout table of a derived PDO's rustdoc: where each field lies, in
//! bits and bytes, as far as the struct itself says. A field's width is
//! known from `bits = N`, from a gap, or from a primitive field type (whose
//! width the expansion checks against the entry's data type); behind a
//! field of a named value type (an enum, a scaled unit) the offsets are
//! left to the compiler, and the table says so instead of guessing.

use quote::quote;

use crate::parse::{Direction, FieldKind, Pdo};

/// The width a field's Rust type states, when it is a primitive: the
/// entry's data type then has this size unless it is a 24-, 40-, 48- or
/// 56-bit integer (which the expansion rejects without `bits = N`).
pub(crate) fn natural_bits(ty: &syn::Type) -> Option<u32> {
    let syn::Type::Path(p) = ty else {
        return None;
    };
    if p.qself.is_some() {
        return None;
    }
    let ident = p.path.get_ident()?.to_string();
    Some(match ident.as_str() {
        "bool" | "u8" | "i8" => 8,
        "u16" | "i16" => 16,
        "u32" | "i32" | "f32" => 32,
        "u64" | "i64" | "f64" => 64,
        _ => return None,
    })
}

/// The rustdoc lines of the struct's inherent `impl` block (which rustdoc
/// shows on the struct's page; a derive cannot document the struct itself).
pub(crate) fn lines(pdo: &Pdo) -> Vec<String> {
    let kind = match pdo.direction {
        Direction::Tpdo => "TPDO",
        Direction::Rpdo => "RPDO",
    };
    let mut rows = Vec::new();
    let mut at = Some(0u32);
    let mut previous: Option<String> = None;
    for f in &pdo.fields {
        let (maps, width) = match &f.kind {
            FieldKind::Entry { path, bits } => {
                let path = quote!(#path).to_string().replace(' ', "");
                match bits {
                    Some(b) => (format!("`{path}`, its low {b} bits"), Some(*b)),
                    None => (format!("`{path}`"), natural_bits(f.ty)),
                }
            }
            FieldKind::Gap(n) => ("gap (dummy entries)".to_string(), Some(*n)),
        };
        let (bits, bytes) = match (at, width) {
            (Some(start), Some(w)) => (format!("{start}..{}", start + w), bytes(start, w)),
            (Some(start), None) => (format!("{start}.. (the entry's size)"), "–".to_string()),
            (None, _) => {
                let after = previous.as_deref().unwrap_or("the previous field");
                (format!("after `{after}`"), "–".to_string())
            }
        };
        rows.push(format!(" | {bits} | {bytes} | `{}` | {maps} |", f.ident));
        at = at.zip(width).map(|(a, w)| a + w);
        previous = Some(f.ident.to_string());
    }
    let length = match at {
        Some(bits) => format!("{} bytes", bits.div_ceil(8)),
        None => "[`Self::LEN`] bytes".to_string(),
    };
    let mut out = vec![
        format!(
            " {kind}{} ({length}), mapped by `#[derive(Pdo)]`.",
            pdo.number
        ),
        String::new(),
        " | Bits | Bytes | Field | Maps |".to_string(),
        " |---|---|---|---|".to_string(),
    ];
    out.extend(rows);
    out.push(String::new());
    out.push(
        " Bits count from bit 0 of byte 0 (little endian); a signed entry is sign-extended from its mapped width. `MAPPING` holds the mapping parameter's entries."
            .to_string(),
    );
    if at.is_none() {
        out.push(String::new());
        out.push(
            " A field of a named value type takes its entry's size, which the compiler knows and this table does not; `MAPPING` has every width."
                .to_string(),
        );
    }
    out
}

/// The bytes a field of `width` bits at bit `start` covers: `2–5`, or
/// `6.0–6.3` (byte.bit) when it does not start and end on byte boundaries.
fn bytes(start: u32, width: u32) -> String {
    let end = start + width - 1;
    if start.is_multiple_of(8) && (end + 1).is_multiple_of(8) {
        let (first, last) = (start / 8, end / 8);
        if first == last {
            first.to_string()
        } else {
            format!("{first}–{last}")
        }
    } else {
        format!("{}.{}–{}.{}", start / 8, start % 8, end / 8, end % 8)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_ranges() {
        assert_eq!(bytes(0, 16), "0–1");
        assert_eq!(bytes(16, 8), "2");
        assert_eq!(bytes(48, 4), "6.0–6.3");
        assert_eq!(bytes(4, 12), "0.4–1.7");
    }

    #[test]
    fn widths_from_primitive_types_only() {
        let ty = |s: &str| syn::parse_str::<syn::Type>(s).unwrap();
        assert_eq!(natural_bits(&ty("i32")), Some(32));
        assert_eq!(natural_bits(&ty("bool")), Some(8));
        assert_eq!(natural_bits(&ty("od::Mode")), None);
        assert_eq!(natural_bits(&ty("<od::Statusword as Entry>::Value")), None);
    }

    #[test]
    fn the_table_of_the_chapters_struct() {
        let input: syn::DeriveInput = syn::parse_quote! {
            #[pdo(tpdo = 2)]
            pub struct StatusPosition {
                #[pdo(entry = drive::od::Statusword)]
                pub status: u16,
                #[pdo(entry = drive::od::PositionActualValue)]
                pub position: i32,
                #[pdo(entry = drive::od::DigitalInputs, bits = 4)]
                pub inputs: u32,
                #[pdo(gap = 4)]
                pub reserved: (),
            }
        };
        let pdo = crate::parse::pdo(&input).unwrap();
        let table = lines(&pdo);
        assert_eq!(table[0], " TPDO2 (7 bytes), mapped by `#[derive(Pdo)]`.");
        assert_eq!(
            table[4..8],
            [
                " | 0..16 | 0–1 | `status` | `drive::od::Statusword` |",
                " | 16..48 | 2–5 | `position` | `drive::od::PositionActualValue` |",
                " | 48..52 | 6.0–6.3 | `inputs` | `drive::od::DigitalInputs`, its low 4 bits |",
                " | 52..56 | 6.4–6.7 | `reserved` | gap (dummy entries) |",
            ]
        );
    }

    #[test]
    fn offsets_after_a_named_value_type_are_left_to_the_compiler() {
        let input: syn::DeriveInput = syn::parse_quote! {
            #[pdo(rpdo = 1)]
            pub struct Command {
                #[pdo(entry = od::Controlword)]
                pub control: <od::Controlword as Entry>::Value,
                #[pdo(entry = od::TargetVelocity)]
                pub velocity: i32,
            }
        };
        let pdo = crate::parse::pdo(&input).unwrap();
        let table = lines(&pdo);
        assert_eq!(
            table[0],
            " RPDO1 ([`Self::LEN`] bytes), mapped by `#[derive(Pdo)]`."
        );
        assert_eq!(
            table[4],
            " | 0.. (the entry's size) | – | `control` | `od::Controlword` |"
        );
        assert_eq!(
            table[5],
            " | after `control` | – | `velocity` | `od::TargetVelocity` |"
        );
        assert!(table.last().unwrap().contains("`MAPPING` has every width"));
    }
}
