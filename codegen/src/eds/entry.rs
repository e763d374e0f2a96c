//! Lowering of one value-carrying section (a VAR or a sub-object) into an [`Entry`].

use super::ini::{Property, Section};
use super::lower::Lowering;
use super::number::{self, parse_value};
use super::sections::{SectionKind, classify};
use crate::diag::Severity;
use crate::ir::{
    Access, DataType, Entry, LimitProblem, Literal, ObjectKind, Origin, Value, ValueKind,
};

/// The access an AccessType token names (CiA 306: ro, wo, rw, rwr, rww,
/// const), in any case.
fn access_type(token: &str) -> Option<Access> {
    [
        Access::Ro,
        Access::Wo,
        Access::Rw,
        Access::Rwr,
        Access::Rww,
        Access::Const,
    ]
    .into_iter()
    .find(|a| a.as_str().eq_ignore_ascii_case(token))
}

impl Lowering<'_> {
    /// Reads one entry. `kind` is the object's kind for a VAR/DOMAIN/DEFTYPE
    /// (sub 0), `Var` for sub-objects. `None` when the entry has no meaning.
    pub(super) fn entry(
        &mut self,
        index: u16,
        sub: u8,
        section: &Section,
        kind: ObjectKind,
    ) -> Option<Entry> {
        let name = self.name(section, || {
            if sub == 0 {
                format!("Object 0x{index:04X}")
            } else {
                format!("Sub-index {sub}")
            }
        });
        let data_type = match section.get("DataType").filter(|p| !p.value.is_empty()) {
            None if kind == ObjectKind::Domain => DataType::Domain,
            None => {
                self.report(
                    Severity::Error,
                    "eds::missing-data-type",
                    section,
                    None,
                    "no DataType; the entry has no meaning without one and is left out".into(),
                );
                return None;
            }
            Some(p) => match number::parse_int(p.value)
                .ok()
                .and_then(|v| u16::try_from(v).ok())
            {
                None => {
                    self.report(
                        Severity::Error,
                        "eds::bad-data-type",
                        section,
                        Some(p),
                        format!(
                            "`{}` is not a data type code; the entry is left out",
                            p.value
                        ),
                    );
                    return None;
                }
                Some(code) => {
                    let data_type = DataType::from_code(code);
                    if let DataType::Other(code) = data_type {
                        let note = if self.doc.section(&format!("{code:04X}")).is_some() {
                            " (a DEFTYPE/DEFSTRUCT of this file)"
                        } else {
                            ""
                        };
                        self.report(Severity::Warning, "eds::unknown-data-type", section, Some(p), format!("data type {code:#06x}{note} is not a CiA 301 basic type (0x0001–0x001B); values of this entry are kept as text"));
                    }
                    data_type
                }
            },
        };
        let access = match section.get("AccessType").filter(|p| !p.value.is_empty()) {
            None => {
                let access = if kind == ObjectKind::DefType {
                    Access::Const
                } else {
                    Access::Ro
                };
                if kind != ObjectKind::DefType {
                    self.report(
                        Severity::Warning,
                        "eds::missing-access",
                        section,
                        None,
                        "no AccessType; read as `ro`".into(),
                    );
                }
                access
            }
            Some(p) => match access_type(p.value.trim()) {
                Some(access) => access,
                None => {
                    self.unknown_access(index, sub, section, p);
                    Access::Ro
                }
            },
        };
        let pdo_mappable = match section.get("PDOMapping").filter(|p| !p.value.is_empty()) {
            None => false,
            Some(p) => match number::parse_int(p.value) {
                Ok(0) => false,
                Ok(1) => true,
                _ => {
                    self.report(
                        Severity::Warning,
                        "eds::bad-pdo-mapping",
                        section,
                        Some(p),
                        format!("PDOMapping must be 0 or 1, not `{}`; read as 0", p.value),
                    );
                    false
                }
            },
        };
        let value = |this: &mut Self, key: &str| -> Option<Literal> {
            // An empty value is absent, except for strings and byte strings,
            // where it is the empty value.
            let text_like = matches!(
                data_type.value_kind(),
                Some(ValueKind::Text | ValueKind::Bytes)
            ) && !key.ends_with("Limit");
            let p = section
                .get(key)
                .filter(|p| text_like || !p.value.is_empty())?;
            this.literal(section, p, data_type)
        };
        let default = value(self, "DefaultValue");
        let low_limit = value(self, "LowLimit");
        let high_limit = value(self, "HighLimit");
        let parameter_value = value(self, "ParameterValue");
        let obj_flags = match section.get("ObjFlags").filter(|p| !p.value.is_empty()) {
            None => None,
            Some(p) => match number::parse_int(p.value)
                .ok()
                .and_then(|v| u32::try_from(v).ok())
            {
                Some(v) => Some(v),
                None => {
                    self.report(
                        Severity::Warning,
                        "eds::bad-number",
                        section,
                        Some(p),
                        format!("ObjFlags `{}` is not a 32-bit number; ignored", p.value),
                    );
                    None
                }
            },
        };
        let denotation = section
            .get("Denotation")
            .map(|p| p.value.to_string())
            .filter(|v| !v.is_empty());
        let entry = Entry {
            subindex: sub,
            name,
            data_type,
            access,
            pdo_mappable,
            default,
            low_limit,
            high_limit,
            parameter_value,
            obj_flags,
            denotation,
            semantics: Default::default(),
            rust_name: None,
            origin: Origin {
                file: self.doc.file.clone(),
                line: section.line,
            },
        };
        self.check_limits(section, &entry);
        Some(entry)
    }

    /// An AccessType CiA 306 does not define: a warning, read as `ro` (see
    /// docs/eds-reader.md), with the overlay that sets the right access.
    fn unknown_access(&mut self, index: u16, sub: u8, section: &Section, p: &Property) {
        let token = p.value.trim();
        // python-canopen keeps the token and tests its letters: readable when
        // it has an `r` (or is `const`), writable when it has a `w`.
        let lower = token.to_ascii_lowercase();
        let (readable, writable) = (lower.contains('r'), lower.contains('w'));
        let python = match (readable, writable) {
            (true, true) => "readable and writable",
            (true, false) => "read-only",
            (false, true) => "write-only",
            (false, false) => "neither readable nor writable",
        };
        let example = if writable && !readable { "wo" } else { "rw" };
        // The template of CompactSubObj entries is the object's own section.
        let compact = sub != 0 && matches!(classify(section.name), SectionKind::Object(_));
        self.report_with_notes(
            Severity::Warning,
            "eds::bad-access",
            section,
            Some(p),
            format!(
                "`{token}` is not an access type (ro, wo, rw, rwr, rww, const); read as `ro`"
            ),
            vec![
                format!(
                    "`ro` is the safe reading: no write to this entry compiles in the generated code \
                     (python-canopen would take `{token}` as {python})"
                ),
                format!(
                    "set the device's real access in a YAML overlay (docs/yaml-tables.md), e.g. \
                     `modify: [{{ index: 0x{index:04X}, sub: {sub}, access: {example} }}]`{}",
                    if compact {
                        ", one item per sub-index of the CompactSubObj"
                    } else {
                        ""
                    }
                ),
            ],
        );
    }

    /// Reads a value of `data_type` from a property; a bad value is a warning and gives `None`.
    pub(super) fn literal(
        &mut self,
        section: &Section,
        p: &Property,
        data_type: DataType,
    ) -> Option<Literal> {
        let warn = |this: &mut Self, code, message| {
            this.report(Severity::Warning, code, section, Some(p), message)
        };
        match parse_value(p.value, data_type) {
            None => {
                // Unknown type: keep an integer when it reads as one, else the text.
                let value = match number::parse_int_expr(p.value) {
                    Ok((v, rel)) => {
                        return Some(Literal {
                            value: Value::Integer(v),
                            plus_node_id: rel,
                            text: p.value.to_string(),
                        });
                    }
                    Err(_) => Value::Text(p.value.to_string()),
                };
                Some(Literal {
                    value,
                    plus_node_id: false,
                    text: p.value.to_string(),
                })
            }
            Some(Ok(parsed)) => {
                if let Some(w) = parsed.warning {
                    warn(
                        self,
                        "eds::value-out-of-range",
                        format!("{w}; kept as written"),
                    );
                }
                Some(parsed.literal)
            }
            Some(Err(e)) => {
                warn(
                    self,
                    "eds::bad-value",
                    format!("{} for {}; the value is ignored", e.0, data_type.name()),
                );
                None
            }
        }
    }

    /// Low limit above high limit, or a default outside the limits.
    fn check_limits(&mut self, section: &Section, entry: &Entry) {
        let text = |l: &Option<Literal>| l.as_ref().map_or(String::new(), |l| l.text.clone());
        let (key, message) = match entry.limit_problem() {
            None => return,
            Some(LimitProblem::LowAboveHigh) => (
                "LowLimit",
                format!(
                    "LowLimit {} is above HighLimit {}",
                    text(&entry.low_limit),
                    text(&entry.high_limit)
                ),
            ),
            Some(problem) => {
                let which = if problem == LimitProblem::DefaultBelowLow {
                    "below LowLimit"
                } else {
                    "above HighLimit"
                };
                let message = format!("DefaultValue {} is {which}", text(&entry.default));
                ("DefaultValue", message)
            }
        };
        let p = section.get(key);
        self.report(Severity::Warning, "eds::limits", section, p, message);
    }
}
