//! The naming table: every generated identifier comes from here.
//!
//! Source names (EDS `ParameterName`, YAML `name`) are free text. They are
//! sanitised into the case Rust expects for the kind of item (German umlauts
//! transliterated, other non-ASCII and punctuation taken as word breaks,
//! a leading digit prefixed, keywords suffixed with `_`). A [`Namespace`]
//! collects every name requested in one scope first and then resolves them
//! together: names that become equal after sanitising are all qualified with
//! their key (index, subindex, code) and reported as one diagnostic naming
//! both origins, so that adding an object never silently renames another.
//!
//! A *fixed* request (a CiA canonical name, a `rust_name:` pin) is never
//! qualified because of a source name; source names equal to a fixed name
//! in the scope, or to a reserved canonical name of the device's profiles
//! (present or not), are qualified with their own key.

use std::collections::{BTreeMap, HashSet};

use heck::{ToShoutySnakeCase, ToSnakeCase, ToUpperCamelCase};
use proc_macro2::{Ident, Span};

use crate::diag::{Diagnostic, Diagnostics, Location, Severity};
use crate::ir::Origin;

mod words;

/// The case of a kind of identifier.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Case {
    /// Types, enum variants.
    UpperCamel,
    /// Modules, fields, functions.
    Snake,
    /// Constants.
    ShoutySnake,
}

/// Rust's strict and reserved keywords (edition 2024) plus the names that
/// cannot be raw identifiers.
const KEYWORDS: &[&str] = &[
    "as",
    "async",
    "await",
    "break",
    "const",
    "continue",
    "crate",
    "dyn",
    "else",
    "enum",
    "extern",
    "false",
    "fn",
    "for",
    "gen",
    "if",
    "impl",
    "in",
    "let",
    "loop",
    "match",
    "mod",
    "move",
    "mut",
    "pub",
    "ref",
    "return",
    "self",
    "Self",
    "static",
    "struct",
    "super",
    "trait",
    "true",
    "type",
    "unsafe",
    "use",
    "where",
    "while",
    "abstract",
    "become",
    "box",
    "do",
    "final",
    "macro",
    "override",
    "priv",
    "try",
    "typeof",
    "unsized",
    "virtual",
    "yield",
    "union",
    "macro_rules",
    "raw",
    "safe",
];

/// `text` as an identifier of `case`, or `""` when nothing usable remains.
pub(crate) fn sanitize(text: &str, case: Case) -> String {
    let mut ascii = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            'a'..='z' | 'A'..='Z' | '0'..='9' => ascii.push(c),
            'ä' => ascii.push_str("ae"),
            'ö' => ascii.push_str("oe"),
            'ü' => ascii.push_str("ue"),
            'Ä' => ascii.push_str("Ae"),
            'Ö' => ascii.push_str("Oe"),
            'Ü' => ascii.push_str("Ue"),
            'ß' => ascii.push_str("ss"),
            _ => ascii.push(' '),
        }
    }
    let ascii = words::mark_words(&ascii);
    let mut name = match case {
        Case::UpperCamel => ascii.to_upper_camel_case(),
        Case::Snake => ascii.to_snake_case(),
        Case::ShoutySnake => ascii.to_shouty_snake_case(),
    };
    if name.is_empty() {
        return name;
    }
    if name.starts_with(|c: char| c.is_ascii_digit()) {
        name.insert_str(
            0,
            match case {
                Case::UpperCamel => "N",
                Case::Snake => "n_",
                Case::ShoutySnake => "N_",
            },
        );
    }
    if KEYWORDS.contains(&name.as_str()) {
        name.push('_');
    }
    name
}

/// The identifier for an already sanitised name.
pub(crate) fn ident(name: &str) -> Ident {
    Ident::new(name, Span::call_site())
}

/// Whether rustdoc accepts `source` as `#[doc(alias)]` of an item called
/// `ident` (no quotes, no whitespace but spaces, none at the ends, not the
/// item's own name).
pub(crate) fn alias_allowed(source: &str, ident: &str) -> bool {
    !source.is_empty()
        && source != ident
        && !source.starts_with(' ')
        && !source.ends_with(' ')
        && !source.chars().any(|c| {
            c == '"' || c == '\'' || (c.is_whitespace() && c != ' ') || crate::text::is_hazard(c)
        })
}

/// A handle to a requested name; resolved by [`Names::get`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct NameId(usize);

struct Request {
    base: String,
    key: String,
    source: String,
    origin: Option<Origin>,
    /// A canonical or pinned name: taken as it is.
    fixed: bool,
    /// A `rust_name:` pin: meeting any other name of the scope is an error.
    pinned: bool,
}

/// One scope of generated names (a module, an enum's variants, a struct's
/// fields, an impl's methods).
pub(crate) struct Namespace {
    scope: String,
    case: Case,
    reserved: Vec<String>,
    /// Canonical names (UpperCamelCase) no source name may take.
    canonical: Option<&'static HashSet<String>>,
    requests: Vec<Request>,
}

/// The resolved names of a [`Namespace`].
pub(crate) struct Names {
    names: Vec<String>,
    /// For a source name qualified because another source name in the scope
    /// became the same: that shared name.
    collided: Vec<Option<String>>,
}

impl Names {
    pub(crate) fn get(&self, id: NameId) -> Ident {
        ident(&self.names[id.0])
    }

    pub(crate) fn text(&self, id: NameId) -> &str {
        &self.names[id.0]
    }

    /// The name `id` shares with another source name of the scope, when
    /// that made it qualified (the only case in which removing another
    /// object can change it).
    pub(crate) fn collided(&self, id: NameId) -> Option<&str> {
        self.collided[id.0].as_deref()
    }
}

impl Namespace {
    /// `scope` says where the names live, for diagnostics ("module `od`").
    pub(crate) fn new(scope: impl Into<String>, case: Case) -> Namespace {
        Namespace {
            scope: scope.into(),
            case,
            reserved: Vec::new(),
            canonical: None,
            requests: Vec::new(),
        }
    }

    /// Reserves canonical names (UpperCamelCase, compared in this scope's
    /// case): a source name equal to one is qualified with its key, whether
    /// or not the object of that name exists.
    pub(crate) fn reserve_canonical(&mut self, names: &'static HashSet<String>) {
        self.canonical = Some(names);
    }

    /// Reserves the type names whose snake case is a constructor generated
    /// types have (`FromValue` vs `from_value`): a type of that name would
    /// make its constructor look like a self-named one.
    pub(crate) fn reserve_constructor_names(&mut self) {
        for name in ["FromRaw", "FromValue", "FromKind", "FromNumber", "FromCode"] {
            self.reserve(name);
        }
    }

    /// A name the generator itself uses in this scope (a method, a fixed
    /// variant); a source name that becomes equal to it is qualified.
    pub(crate) fn reserve(&mut self, name: &str) {
        self.reserved.push(name.to_string());
    }

    /// Requests a name for `source`; `key` tells it apart from others when
    /// needed (`x2001`, `sub 3`, `code 0x10`) and names it when the source
    /// name has nothing usable.
    pub(crate) fn request(&mut self, source: &str, key: &str, origin: Option<&Origin>) -> NameId {
        self.requests.push(Request {
            base: sanitize(source, self.case),
            key: key.to_string(),
            source: source.to_string(),
            origin: origin.cloned(),
            fixed: false,
            pinned: false,
        });
        NameId(self.requests.len() - 1)
    }

    /// Requests a fixed name (a canonical name, a pin): `name` is taken as
    /// it is (sanitised into this scope's case); source names give way to
    /// it. Two fixed names that meet are numbered and reported.
    pub(crate) fn request_fixed(
        &mut self,
        name: &str,
        key: &str,
        origin: Option<&Origin>,
    ) -> NameId {
        let base = sanitize(name, self.case);
        self.requests.push(Request {
            base: if base.is_empty() {
                sanitize(key, self.case)
            } else {
                base
            },
            key: key.to_string(),
            source: name.to_string(),
            origin: origin.cloned(),
            fixed: true,
            pinned: false,
        });
        NameId(self.requests.len() - 1)
    }

    /// Requests a pinned name (`rust_name:`, already an identifier of this
    /// scope's case): fixed like a canonical name, and any other name of the
    /// scope that is the same (a source, canonical, generated or pinned name)
    /// is a `gen::rust-name-collision` error naming both.
    pub(crate) fn request_pinned(
        &mut self,
        pin: &str,
        key: &str,
        origin: Option<&Origin>,
    ) -> NameId {
        let id = self.request_fixed(pin, key, origin);
        self.requests[id.0].pinned = true;
        id
    }

    /// Resolves every request; collisions are reported into `diags`.
    pub(crate) fn resolve(mut self, diags: &mut Diagnostics) -> Names {
        let case = self.case;
        // A source name with nothing usable is named by its key; that name
        // takes part in the collision check like any other.
        for r in &mut self.requests {
            if r.base.is_empty() {
                r.base = sanitize(&r.key, case);
            }
        }
        let qualified = |r: &Request| sanitize(&format!("{} {}", r.base, r.key), case);
        // Collisions among source names; fixed names stand apart.
        let mut groups: BTreeMap<&str, Vec<usize>> = BTreeMap::new();
        for (i, r) in self.requests.iter().enumerate().filter(|(_, r)| !r.fixed) {
            groups.entry(r.base.as_str()).or_default().push(i);
        }
        let fixed: HashSet<&str> = self
            .requests
            .iter()
            .filter(|r| r.fixed)
            .map(|r| r.base.as_str())
            .collect();
        let canonical = |base: &str| {
            self.canonical
                .is_some_and(|set| set.contains(&sanitize(base, Case::UpperCamel)))
        };
        let mut names: Vec<String> = Vec::with_capacity(self.requests.len());
        let mut collided: Vec<Option<String>> = Vec::with_capacity(self.requests.len());
        for r in &self.requests {
            let clash_reserved = self.reserved.contains(&r.base);
            if r.fixed {
                names.push(if clash_reserved {
                    qualified(r)
                } else {
                    r.base.clone()
                });
                collided.push(None);
                continue;
            }
            let group = &groups[r.base.as_str()];
            let taken = clash_reserved || fixed.contains(r.base.as_str()) || canonical(&r.base);
            names.push(if group.len() > 1 || taken {
                qualified(r)
            } else {
                r.base.clone()
            });
            collided.push((group.len() > 1).then(|| r.base.clone()));
        }
        for (base, members) in &groups {
            let clash_reserved = self.reserved.iter().any(|n| n == base);
            if members.len() > 1 {
                let renamed: Vec<&str> = members.iter().map(|&i| names[i].as_str()).collect();
                report(diags, &self.scope, base, members, &self.requests, &renamed);
            } else if clash_reserved {
                let r = &self.requests[members[0]];
                diags.push(diagnostic(
                    r.origin.as_ref(),
                    format!(
                        "`{}` becomes `{base}` in {}, a name the generator uses there; it is named `{}`",
                        r.source, self.scope, names[members[0]]
                    ),
                    Vec::new(),
                ));
            }
        }
        // A pin that meets another name is an error, not a qualification.
        let mut pin_reported = vec![false; self.requests.len()];
        for (i, r) in self.requests.iter().enumerate().filter(|(_, r)| r.pinned) {
            let mut others: Vec<String> = Vec::new();
            if self.reserved.contains(&r.base) {
                others.push(format!("`{}`, a name the generator uses there", r.base));
            }
            for (j, other) in self.requests.iter().enumerate() {
                if j == i || other.base != r.base || (other.pinned && j < i) {
                    continue;
                }
                let what = if other.pinned {
                    "the pin `rust_name: "
                } else if other.fixed {
                    "the standard name `"
                } else {
                    "`"
                };
                others.push(format!(
                    "{what}{}` ({})",
                    other.source,
                    at(other.origin.as_ref())
                ));
                pin_reported[j] = true;
            }
            if others.is_empty() {
                continue;
            }
            pin_reported[i] = true;
            let mut d = diagnostic(
                r.origin.as_ref(),
                format!(
                    "`rust_name: {}` ({}) collides in {} with {}; a pinned name must be unique in its scope: pin another name",
                    r.base,
                    at(r.origin.as_ref()),
                    self.scope,
                    others.join(" and "),
                ),
                Vec::new(),
            );
            d.severity = Severity::Error;
            d.code = "gen::rust-name-collision";
            diags.push(d);
        }
        // Qualified names may still meet each other or a reserved name:
        // number them, in request order, and say so (unless a pin's
        // collision was already reported).
        let mut taken: Vec<String> = self.reserved.clone();
        for (i, name) in names.iter_mut().enumerate() {
            if taken.contains(name) {
                let mut n = 2;
                let numbered = |n: u32| format!("{name}{}N{n}", sep(case));
                while taken.contains(&numbered(n)) {
                    n += 1;
                }
                let new = numbered(n);
                let r = &self.requests[i];
                // A pin's collision is an error already (the generated code
                // is not used); the numbering only keeps the names apart.
                if !pin_reported[i] {
                    diags.push(diagnostic(
                        r.origin.as_ref(),
                        format!(
                            "`{}` would be `{name}` in {}, which is taken even after qualifying; it is named `{new}`",
                            r.source, self.scope
                        ),
                        Vec::new(),
                    ));
                }
                if collided[i].is_none() {
                    collided[i] = Some(name.clone());
                }
                *name = new;
            }
            taken.push(name.clone());
        }
        Names { names, collided }
    }
}

fn sep(case: Case) -> &'static str {
    match case {
        Case::UpperCamel => "",
        Case::Snake | Case::ShoutySnake => "_",
    }
}

fn report(
    diags: &mut Diagnostics,
    scope: &str,
    base: &str,
    members: &[usize],
    requests: &[Request],
    renamed: &[&str],
) {
    let first = &requests[members[0]];
    let mut notes = Vec::new();
    for (&i, name) in members.iter().zip(renamed) {
        let r = &requests[i];
        notes.push(format!(
            "`{}` at {} is named `{name}`",
            r.source,
            at(r.origin.as_ref())
        ));
    }
    let others: Vec<String> = members[1..]
        .iter()
        .map(|&i| {
            let r = &requests[i];
            format!("`{}` ({})", r.source, at(r.origin.as_ref()))
        })
        .collect();
    diags.push(diagnostic(
        first.origin.as_ref(),
        format!(
            "`{}` ({}) and {} all become `{base}` in {scope}; each is qualified with its key (while the others exist: rename one in the source, or pin its Rust name with `rust_name:` in a YAML table or overlay, to make the names stable)",
            first.source,
            at(first.origin.as_ref()),
            others.join(" and "),
        ),
        notes,
    ));
}

fn at(origin: Option<&Origin>) -> String {
    match origin {
        Some(o) if o.line > 0 => format!("{}:{}", o.file, o.line),
        Some(o) => o.file.clone(),
        None => "generated".into(),
    }
}

fn diagnostic(origin: Option<&Origin>, message: String, notes: Vec<String>) -> Diagnostic {
    Diagnostic {
        severity: Severity::Warning,
        code: "gen::name-collision",
        file: origin.map(|o| o.file.clone()).unwrap_or_default(),
        location: Location {
            line: origin.map(|o| o.line).filter(|&l| l > 0),
            ..Location::default()
        },
        message,
        notes,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sanitising() {
        assert_eq!(
            sanitize("Motor-Temperatur (°C)", Case::UpperCamel),
            "MotorTemperaturC"
        );
        assert_eq!(sanitize("Größe über", Case::Snake), "groesse_ueber");
        assert_eq!(sanitize("1st value", Case::Snake), "n_1st_value");
        assert_eq!(sanitize("1st value", Case::UpperCamel), "N1stValue");
        assert_eq!(sanitize("type", Case::Snake), "type_");
        assert_eq!(sanitize("self", Case::Snake), "self_");
        assert_eq!(sanitize("Self", Case::UpperCamel), "Self_");
        assert_eq!(sanitize("\"]; } 🚀", Case::Snake), "");
    }

    #[test]
    fn collisions_are_qualified_and_reported() {
        let o = |line| Origin {
            file: "a.eds".into(),
            line,
        };
        let mut ns = Namespace::new("module `od`", Case::UpperCamel);
        ns.reserve("Unknown");
        let a = ns.request("Reserved", "x2001", Some(&o(10)));
        let b = ns.request("reserved!", "x2002", Some(&o(20)));
        let c = ns.request("Speed", "x2003", Some(&o(30)));
        let d = ns.request("unknown", "x2004", Some(&o(40)));
        let e = ns.request("🚀", "x2005", Some(&o(50)));
        let f = ns.request("🚀", "sub 1", Some(&o(60)));
        let g = ns.request("Sub1", "sub 2", Some(&o(70)));
        let mut diags = Diagnostics::new();
        let names = ns.resolve(&mut diags);
        assert_eq!(names.text(a), "ReservedX2001");
        assert_eq!(names.text(b), "ReservedX2002");
        assert_eq!(names.text(c), "Speed");
        assert_eq!(names.text(d), "UnknownX2004");
        assert_eq!(names.text(e), "X2005");
        // A key-made name meets a real one: both qualified, and reported.
        assert_eq!(names.text(f), "Sub1Sub1");
        assert_eq!(names.text(g), "Sub1Sub2");
        assert_eq!(diags.len(), 3);
        let text = diags.to_string();
        assert!(
            text.contains("a.eds:10") && text.contains("a.eds:20"),
            "{text}"
        );
    }

    #[test]
    fn pins_are_kept_and_their_collisions_are_errors() {
        let o = |line| Origin {
            file: "a.yaml".into(),
            line,
        };
        let mut ns = Namespace::new("module `od`", Case::UpperCamel);
        ns.reserve("Unknown");
        let pin = ns.request_pinned("Speed", "x2000", Some(&o(10)));
        let source = ns.request("speed", "x2001", Some(&o(20)));
        let free = ns.request_pinned("Gain", "x2002", Some(&o(30)));
        let reserved = ns.request_pinned("Unknown", "x2003", Some(&o(40)));
        let mut diags = Diagnostics::new();
        let names = ns.resolve(&mut diags);
        assert_eq!(names.text(pin), "Speed");
        assert_eq!(names.text(free), "Gain");
        assert_ne!(names.text(source), "Speed");
        assert_ne!(names.text(reserved), "Unknown");
        let errors: Vec<&Diagnostic> = diags
            .iter()
            .filter(|d| d.code == "gen::rust-name-collision" && d.severity == Severity::Error)
            .collect();
        assert_eq!(errors.len(), 2, "{}", diags.render());
        assert!(
            errors[0].message.contains("a.yaml:10") && errors[0].message.contains("a.yaml:20"),
            "{}",
            errors[0].message
        );
        // No second report of the same clash as a warning.
        assert_eq!(diags.len(), 2, "{}", diags.render());
    }

    #[test]
    fn aliases() {
        assert!(alias_allowed("Motor speed", "MotorSpeed"));
        assert!(!alias_allowed("Speed", "Speed"));
        assert!(!alias_allowed("say \"hi\"", "SayHi"));
        assert!(!alias_allowed(" x", "X"));
        assert!(!alias_allowed("a\tb", "AB"));
    }
}
