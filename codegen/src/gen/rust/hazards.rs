//! Warnings for source text with control or bidirectional-text characters
//! (`gen::unsafe-text`). The generated file gets such characters as
//! `\u{...}` escapes ([`crate::text::code`], applied to the whole file in
//! [`super::generate`]); this names each text that had one, with the file
//! and line it came from, so that the user can fix the input.

use crate::diag::{Diagnostic, Diagnostics, Location, Severity};
use crate::ir::{Device, Origin, PdoDirection, ValueTable};
use crate::text::{is_bidi, is_hazard};

/// Pushes one warning per text of `device` that holds a hazard.
pub(super) fn warn(device: &Device, diags: &mut Diagnostics) {
    let mut w = Walk {
        diags,
        file_origin: Origin {
            file: device.source.clone(),
            line: 0,
        },
    };
    let at = w.file_origin.clone();
    let id = &device.identity;
    w.opt(&at, "device", "vendor name", &id.vendor_name);
    w.opt(&at, "device", "product name", &id.product_name);
    w.opt(&at, "device", "order code", &id.order_code);
    w.opt(&at, "device", "description", &device.file_info.description);
    w.opt(&at, "device", "created by", &device.file_info.created_by);
    for line in &device.comments {
        w.text(&at, "device", "comment", line);
    }
    for object in device.objects.values() {
        let place = format!("0x{:04X}", object.index);
        w.text(&object.origin, &place, "name", &object.name);
        w.opt(&object.origin, &place, "denotation", &object.denotation);
        for entry in object.entries.values() {
            let place = format!("0x{:04X} sub {}", object.index, entry.subindex);
            let at = &entry.origin;
            // A VAR's entry repeats its object's name: warned once.
            if entry.name != object.name {
                w.text(at, &place, "name", &entry.name);
            }
            w.opt(at, &place, "denotation", &entry.denotation);
            let s = &entry.semantics;
            w.opt(at, &place, "description", &s.description);
            w.opt(at, &place, "unit", &s.unit);
            w.values(at, &place, &s.values);
            for field in &s.bits {
                let place = format!("{place} bit {}", field.lsb);
                w.text(&field.origin, &place, "name", &field.name);
                w.opt(&field.origin, &place, "text", &field.text);
                w.opt(&field.origin, &place, "unit", &field.unit);
                w.values(&field.origin, &place, &field.values);
            }
            for (i, p) in s.patterns.iter().enumerate() {
                let place = format!("{place} state pattern {}", i + 1);
                w.text(&p.origin, &place, "name", &p.name);
                w.opt(&p.origin, &place, "text", &p.text);
            }
        }
    }
    for (i, table) in device.error_tables.iter().enumerate() {
        let place = format!("error table {}", i + 1);
        w.text(&table.origin, &place, "name", &table.name);
        w.opt(&table.origin, &place, "description", &table.description);
        for code in &table.codes {
            let place = format!("{place} code 0x{:04X}", code.code);
            w.text(&code.origin, &place, "name", &code.name);
            w.opt(&code.origin, &place, "text", &code.text);
            w.opt(&code.origin, &place, "reaction", &code.reaction);
            w.opt(&code.origin, &place, "remedy", &code.remedy);
        }
    }
    for label in &device.pdo_labels {
        let place = match label.direction {
            PdoDirection::Rpdo => format!("RPDO{}", label.number),
            PdoDirection::Tpdo => format!("TPDO{}", label.number),
        };
        w.text(&label.origin, &place, "name", &label.name);
        w.opt(&label.origin, &place, "description", &label.description);
    }
}

struct Walk<'a> {
    diags: &'a mut Diagnostics,
    file_origin: Origin,
}

impl Walk<'_> {
    fn opt(&mut self, origin: &Origin, place: &str, what: &str, text: &Option<String>) {
        if let Some(text) = text {
            self.text(origin, place, what, text);
        }
    }

    fn values(&mut self, origin: &Origin, place: &str, table: &Option<ValueTable>) {
        let Some(table) = table else { return };
        self.text(origin, place, "fallback value name", &table.other);
        for v in &table.named {
            let place = format!("{place} value {}", v.low);
            self.text(&v.origin, &place, "name", &v.name);
            self.opt(&v.origin, &place, "text", &v.text);
        }
    }

    fn text(&mut self, origin: &Origin, place: &str, what: &str, text: &str) {
        let Some(c) = text.chars().find(|&c| is_hazard(c)) else {
            return;
        };
        let (kind, effect) = if is_bidi(c) {
            (
                "a bidirectional-text control",
                "which can make text read in another order than it is written",
            )
        } else {
            (
                "a control character",
                "which can move the cursor, recolour or retitle a terminal",
            )
        };
        let origin = if origin.file.is_empty() {
            &self.file_origin
        } else {
            origin
        };
        self.diags.push(Diagnostic {
            severity: Severity::Warning,
            code: "gen::unsafe-text",
            file: origin.file.clone(),
            location: Location {
                line: (origin.line > 0).then_some(origin.line),
                span: None,
                section: None,
                key: Some(format!("{place} {what}")),
            },
            message: format!(
                "holds {kind} (U+{:04X}), {effect}",
                u32::from(c)
            ),
            notes: vec![
                "the generated code writes such characters as `\\u{...}` escapes; remove them from the input"
                    .into(),
            ],
        });
    }
}
