//! A compact listing of the generated API of one device, one line per
//! public item (docs/api-listing.md), meant to be locked in a snapshot so
//! that a device update shows as a diff of a few lines.
//!
//! Every name comes from the plans the generator writes out (`od_plan`, the
//! error plan, the PDO plan), so the listing cannot drift from the code.

use std::fmt::Write as _;

use quote::quote;

use super::naming::Names;
use super::od_plan::{self, EntryPlan};
use super::values::Plan;
use super::{Options, entries, errors, generate, pdo};
use crate::diag::Diagnostics;
use crate::ir::{Device, Entry, ErrorTableKind, Object, ObjectKind, PdoDirection, ValueTable};

/// The API listing of one device and the generator's warnings.
#[derive(Debug, Clone)]
pub struct ApiListing {
    /// One line per public item, each ending in `\n`.
    pub text: String,
    pub warnings: Diagnostics,
}

/// The listing of the API [`generate`] gives `device` with `options`; its
/// errors (and, with `options.strict`, warnings) are those of [`generate`].
pub fn api_listing(device: &Device, options: &Options) -> Result<ApiListing, Diagnostics> {
    let output = generate(device, options)?;
    Ok(ApiListing {
        // Units and names from the input: control and bidi characters as
        // `\u{...}`, as in the generated code.
        text: crate::text::code(&listing(device)).into_owned(),
        warnings: output.warnings,
    })
}

/// Where a line sorts: `od` by (index, subindex; -1 for a module), `pdo` by
/// mapping index, `errors` by table name; then in the order written.
#[derive(PartialEq, Eq, PartialOrd, Ord)]
enum Key {
    Od(u16, i16),
    Pdo(u16),
    Errors(String),
}

struct Lines(Vec<(Key, usize, String)>);

impl Lines {
    fn push(&mut self, key: Key, columns: &[&str]) {
        let seq = self.0.len();
        self.0.push((key, seq, columns.join("\t")));
    }
}

/// The listing of a device that generates (no diagnostics: the caller has
/// them from `generate`).
fn listing(device: &Device) -> String {
    let mut scratch = Diagnostics::new();
    let error_plans = errors::plan(device, &mut scratch);
    let od = od_plan::plan(device, &error_plans, &mut scratch);
    let rt = quote!(::eds2rust_runtime);
    let mut cx = entries::Ctx {
        device,
        rt: &rt,
        errors: &error_plans,
        diags: &mut scratch,
    };
    let infos = super::od_module::emit(&mut cx, &mut |_| {});
    let pdos = pdo::plan(device, &infos, &mut scratch);

    let mut lines = Lines(Vec::new());
    for root in &od.root {
        let key = format!("0x{:04X}", root.object.index);
        let sub = i16::from(root.entry.entry.subindex);
        entry_lines(
            &mut lines,
            (root.object.index, sub, &key),
            &root.entry,
            "od",
            &od.root_names,
            &error_plans,
        );
    }
    for m in &od.modules {
        let module = format!("od::{}", m.module);
        let index = m.object.index;
        lines.push(
            Key::Od(index, -1),
            &[&module, &format!("0x{index:04X}"), kind_text(m.object)],
        );
        for e in &m.entries {
            let (sub, last) = e.subs();
            // An indexed type covers a range: `0x1003.1..254`.
            let key = if e.is_indexed() {
                format!("0x{index:04X}.{sub}..{last}")
            } else {
                format!("0x{index:04X}.{sub}")
            };
            entry_lines(
                &mut lines,
                (index, i16::from(sub), &key),
                e,
                &module,
                &m.names,
                &error_plans,
            );
        }
    }
    for p in &pdos {
        pdo_line(&mut lines, p);
    }
    for plan in &error_plans {
        let table = &device.error_tables[plan.table];
        let key = || Key::Errors(table.name.clone());
        let name = clean(&table.name);
        let codes: Vec<String> = table
            .codes
            .iter()
            .map(|c| format!("{:#X} {:?}", c.code, c.name))
            .collect();
        lines.push(
            key(),
            &[
                &format!("errors::{}", plan.ident),
                &name,
                "enum",
                &codes.join(", "),
            ],
        );
        let kind = match table.kind {
            ErrorTableKind::Emcy => "emcy",
            ErrorTableKind::Device => "device",
            ErrorTableKind::SdoAbort => "sdo-abort",
        };
        lines.push(
            key(),
            &[
                &format!("errors::{}", plan.code_ident),
                &name,
                &format!("code({})", plan.raw.tokens()),
                &format!("{kind}, kind=errors::{}", plan.ident),
            ],
        );
    }
    lines.0.sort();
    let mut out = String::new();
    for (_, _, line) in lines.0 {
        out.push_str(&line);
        out.push('\n');
    }
    out
}

/// A PDO struct: `pdo::Tpdo1Feedback → 0x1A00 → tpdo 1 → 8 bytes →
/// position@0..16:od::feedback::PositionValue, _@16..24, …`.
fn pdo_line(lines: &mut Lines, p: &pdo::Planned) {
    let layout = &p.layout;
    let mut fields: Vec<(u32, String)> = layout
        .fields
        .iter()
        .map(|f| {
            let ty = match &f.info.value {
                Some(path) => path
                    .iter()
                    .map(ToString::to_string)
                    .collect::<Vec<_>>()
                    .join("::"),
                None => f.info.value_tokens(0).to_string(),
            };
            let name = p.fields.text(f.name);
            let end = f.offset + f.width;
            (f.offset, format!("{name}@{}..{end}:{ty}", f.offset))
        })
        .collect();
    fields.extend(
        layout
            .gaps
            .iter()
            .map(|&(offset, width, _)| (offset, format!("_@{offset}..{}", offset + width))),
    );
    fields.sort();
    let fields: Vec<String> = fields.into_iter().map(|(_, f)| f).collect();
    let direction = match layout.direction {
        PdoDirection::Rpdo => "rpdo",
        PdoDirection::Tpdo => "tpdo",
    };
    let index = layout.mapping.index;
    lines.push(
        Key::Pdo(index),
        &[
            &format!("pdo::{}", p.ident),
            &format!("0x{index:04X}"),
            &format!("{direction} {}", layout.number),
            &format!("{} bytes", layout.total.div_ceil(8)),
            &fields.join(", "),
        ],
    );
}

fn kind_text(object: &Object) -> &'static str {
    match object.kind {
        ObjectKind::Array => "module array",
        _ => "module record",
    }
}

/// The line of an entry's zero-sized type and those of its value types.
fn entry_lines(
    lines: &mut Lines,
    (index, sub, key): (u16, i16, &str),
    e: &EntryPlan,
    module: &str,
    names: &Names,
    error_plans: &[errors::ErrorPlan],
) {
    let entry: &Entry = e.entry;
    let k = || Key::Od(index, sub);
    let value_type = od_plan::value_type_path(&e.value, module, names, error_plans);
    let s = &entry.semantics;
    let unit = unit_text(s.unit.as_deref(), s.scale, s.offset);
    let generics = if e.is_indexed() { "<SUB>" } else { "" };
    lines.push(
        k(),
        &[
            &format!("{module}::{}{generics}", names.text(e.zst)),
            key,
            &value_type,
            entry.access.as_str(),
            if unit.is_empty() { "-" } else { &unit },
            if entry.pdo_mappable { "pdo" } else { "-" },
        ],
    );
    let path = |id| format!("{module}::{}", names.text(id));
    match &e.value {
        Plan::Prim(_) | Plan::Bytes(_) | Plan::Error(_) | Plan::Runtime { .. } => {}
        Plan::Scaled { raw, .. } => {
            lines.push(
                k(),
                &[
                    &value_type,
                    key,
                    &format!("scaled({})", raw.tokens()),
                    &unit,
                ],
            );
        }
        Plan::Enum {
            kind, raw, number, ..
        } => {
            let table = s.values.as_ref().expect("planned only with a value table");
            let mut content = format!("kind={}", path(*kind));
            if let Some(number) = number {
                let _ = write!(content, ", number={}", path(*number));
            }
            lines.push(
                k(),
                &[
                    &value_type,
                    key,
                    &format!("newtype({})", raw.tokens()),
                    &content,
                ],
            );
            let number_ty = number.map_or_else(|| raw.tokens().to_string(), &path);
            lines.push(
                k(),
                &[
                    &path(*kind),
                    key,
                    "enum",
                    &values_text(table, *raw, &number_ty),
                ],
            );
            if let (Some(number), Some((low, high))) = (number, table.numeric) {
                lines.push(
                    k(),
                    &[
                        &path(*number),
                        key,
                        &format!("scaled({})", raw.tokens()),
                        &format!("{unit}, range {}..={}", num(low), num(high)),
                    ],
                );
            }
        }
        Plan::Bits {
            raw, fields, state, ..
        } => {
            let mut parts = Vec::new();
            for (field, enum_name) in s.bits.iter().zip(fields) {
                let span = if field.width == 1 {
                    format!("@{}", field.lsb)
                } else {
                    format!("@{}..{}", field.lsb, field.lsb + field.width)
                };
                let mut part = format!("{:?}{span}", field.name);
                if let Some(id) = enum_name {
                    let _ = write!(part, ":{}", path(*id));
                }
                let unit = unit_text(field.unit.as_deref(), field.scale, None);
                if !unit.is_empty() {
                    let _ = write!(part, " {unit}");
                }
                parts.push(part);
            }
            if let Some(state) = state {
                parts.push(format!("state={}", path(*state)));
            }
            lines.push(
                k(),
                &[
                    &value_type,
                    key,
                    &format!("bits({})", raw.tokens()),
                    &parts.join(", "),
                ],
            );
            for (field, enum_name) in s.bits.iter().zip(fields) {
                if let (Some(id), Some(table)) = (enum_name, &field.values) {
                    let field_raw = super::prim::Prim::int(false, field.width);
                    let number_ty = field_raw.tokens().to_string();
                    lines.push(
                        k(),
                        &[
                            &path(*id),
                            key,
                            "enum",
                            &values_text(table, field_raw, &number_ty),
                        ],
                    );
                }
            }
            if let Some(state) = state {
                let patterns: Vec<String> = s
                    .patterns
                    .iter()
                    .map(|p| format!("{:?} {:#X}/{:#X}", p.name, p.value, p.mask))
                    .collect();
                lines.push(k(), &[&path(*state), key, "state", &patterns.join(", ")]);
            }
        }
    }
}

/// `unit=mm scale=0.1 offset=-40`, the parts there are.
fn unit_text(unit: Option<&str>, scale: Option<f64>, offset: Option<f64>) -> String {
    let mut parts = Vec::new();
    if let Some(unit) = unit {
        parts.push(format!("unit={:?}", unit));
    }
    if let Some(scale) = scale {
        parts.push(format!("scale={scale}"));
    }
    if let Some(offset) = offset {
        parts.push(format!("offset={offset}"));
    }
    parts.join(" ")
}

/// A value table: `number(T) 0x0..=0xFAFF, 0xFB00 "Clear error", …, other "Invalid"`
/// (no `other` when the table covers every raw value of `raw`).
fn values_text(table: &ValueTable, raw: super::prim::Prim, number_ty: &str) -> String {
    let mut parts = Vec::new();
    if let Some((low, high)) = table.numeric {
        parts.push(format!("number({number_ty}) {}..={}", num(low), num(high)));
    }
    for named in &table.named {
        let raw = if named.is_range() {
            format!("{}..={}", num(named.low), num(named.high))
        } else {
            num(named.low)
        };
        parts.push(format!("{raw} {:?}", named.name));
    }
    if !super::enums::covers_all(table, raw) {
        parts.push(format!("other {:?}", table.other));
    }
    parts.join(", ")
}

fn num(v: i128) -> String {
    if v < 0 {
        format!("-{:#X}", v.unsigned_abs())
    } else {
        format!("{v:#X}")
    }
}

/// Source text as one column: tabs and line breaks become spaces.
fn clean(text: &str) -> String {
    text.replace(['\t', '\n', '\r'], " ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_hex_with_sign() {
        assert_eq!(num(0), "0x0");
        assert_eq!(num(0xFB00), "0xFB00");
        assert_eq!(num(-2), "-0x2");
    }

    #[test]
    fn unit_text_lists_the_parts_there_are() {
        assert_eq!(unit_text(None, None, None), "");
        assert_eq!(
            unit_text(Some("mm"), Some(0.1), Some(-40.0)),
            "unit=\"mm\" scale=0.1 offset=-40"
        );
    }

    #[test]
    fn columns_never_hold_tabs() {
        assert_eq!(clean("a\tb\nc"), "a b c");
    }
}
