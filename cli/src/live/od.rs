//! The object table of `--od FILE` and how the user names objects: by key
//! (`0x6041`, `0x1018.1`, `0x1018sub1`, `0x1018:1`), by object name (the
//! EDS ParameterName, any case), by `Object.Sub` name, or by the generated
//! Rust name (`Statusword`, `identity::VendorId`, as `eds2rust api` lists
//! them), with "did you mean" for unknown names.

use std::cell::OnceCell;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use eds2rust::build::load_device;
use eds2rust::input::Options;
use eds2rust::ir::{Device, Entry, Object, ObjectKind};

use super::LiveError;
use super::values::parse_int;

/// What a name stands for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Target {
    /// A whole object (every entry of an ARRAY/RECORD, sub 0 of a VAR).
    Object(u16),
    Entry(u16, u8),
    /// An array element type (`PreDefinedErrorField<SUB>`) with its subs.
    Element(u16, u8, u8),
}

/// A loaded object dictionary with its names.
#[derive(Debug)]
pub struct Od {
    pub device: Device,
    /// Normalized name → (the name as written, what it names).
    names: OnceCell<BTreeMap<String, Vec<(String, Target)>>>,
}

/// The names of `device`: object and entry names, and the Rust names of
/// the generated API when the device generates.
fn names_of(device: &Device) -> BTreeMap<String, Vec<(String, Target)>> {
    let mut names = Vec::new();
    for object in device.objects.values() {
        if object.index < 0x1000 {
            continue;
        }
        names.push((object.name.clone(), Target::Object(object.index)));
        if object.kind != ObjectKind::Var && object.kind != ObjectKind::Domain {
            for entry in object.entries.values() {
                let t = Target::Entry(object.index, entry.subindex);
                names.push((format!("{}.{}", object.name, entry.name), t));
                names.push((entry.name.clone(), t));
            }
        }
    }
    let options = eds2rust::r#gen::rust::Options::default();
    if let Ok(listing) = eds2rust::r#gen::rust::api_listing(device, &options) {
        names.extend(rust_names(&listing.text));
    }
    let mut map: BTreeMap<String, Vec<(String, Target)>> = BTreeMap::new();
    for (name, target) in names {
        // A VAR is its one entry, whichever way it is named.
        let target = match target {
            Target::Object(i)
                if device
                    .objects
                    .get(&i)
                    .is_some_and(|o| matches!(o.kind, ObjectKind::Var | ObjectKind::Domain)) =>
            {
                Target::Entry(i, 0)
            }
            t => t,
        };
        let list = map.entry(normalize(&name)).or_default();
        if !list.iter().any(|(n, t)| *t == target && *n == name) {
            list.push((name, target));
        }
    }
    map
}

/// Lower-case letters and digits only: `Vendor-ID`, `vendor_id` and
/// `VendorId` are one name.
fn normalize(name: &str) -> String {
    name.chars()
        .filter(char::is_ascii_alphanumeric)
        .map(|c| c.to_ascii_lowercase())
        .collect()
}

impl Od {
    /// Reads FILE (EDS, DCF or YAML table); errors are usage errors with
    /// the file's diagnostics.
    pub fn load(path: &Path) -> Result<Od, LiveError> {
        Od::load_with_overlays(path, &[])
    }

    /// [`Od::load`] with YAML overlays applied in order.
    pub fn load_with_overlays(path: &Path, overlays: &[PathBuf]) -> Result<Od, LiveError> {
        let loaded = load_device(path, overlays, &Options::lenient());
        match loaded.device {
            Some(device) if !loaded.diagnostics.has_errors() => Ok(Od::new(device)),
            _ => {
                let mut d = loaded.diagnostics;
                d.errors_first();
                Err(LiveError::Usage(format!(
                    "{}{}: cannot be read as an object dictionary ({} errors)",
                    d.render_severity(eds2rust::diag::Severity::Error),
                    path.display(),
                    d.error_count().max(1)
                )))
            }
        }
    }

    /// `device` with its names, which are worked out on the first lookup
    /// by name (the Rust names need the generator).
    pub fn new(device: Device) -> Od {
        Od {
            device,
            names: OnceCell::new(),
        }
    }

    fn names(&self) -> &BTreeMap<String, Vec<(String, Target)>> {
        self.names.get_or_init(|| names_of(&self.device))
    }

    /// The object and entry at (index, sub).
    pub fn entry(&self, index: u16, sub: u8) -> Option<(&Object, &Entry)> {
        let object = self.device.objects.get(&index)?;
        Some((object, object.entries.get(&sub)?))
    }

    /// The (index, sub) pairs `text` names: one entry, or every entry of an
    /// ARRAY/RECORD named as a whole.
    pub fn resolve(&self, text: &str) -> Result<Vec<(u16, u8)>, LiveError> {
        if let Some((index, sub)) = parse_key(text)? {
            return match sub {
                Some(sub) => {
                    if self.entry(index, sub).is_none() {
                        return Err(self.missing_key(index, Some(sub)));
                    }
                    Ok(vec![(index, sub)])
                }
                None => self
                    .whole(index)
                    .ok_or_else(|| self.missing_key(index, None)),
            };
        }
        let (base, element) = split_element(text);
        let Some(found) = self.names().get(&normalize(base)) else {
            return Err(self.unknown(text));
        };
        let mut targets: Vec<Target> = found.iter().map(|(_, t)| *t).collect();
        targets.sort();
        targets.dedup();
        let target = match targets.as_slice() {
            [one] => *one,
            _ => {
                // The same entry under two spellings is one entry.
                let mut all: Vec<String> = found
                    .iter()
                    .map(|(name, t)| format!("{name} ({})", target_key(*t)))
                    .collect();
                all.sort();
                return Err(LiveError::Usage(format!(
                    "`{text}` names more than one object: {}; give its key",
                    all.join(", ")
                )));
            }
        };
        match (target, element) {
            (Target::Object(index), None) => self.whole(index).ok_or_else(|| self.unknown(text)),
            (Target::Entry(index, sub), None) => Ok(vec![(index, sub)]),
            (Target::Element(index, first, last), Some(sub)) => {
                if sub < first || sub > last || self.entry(index, sub).is_none() {
                    return Err(LiveError::Usage(format!(
                        "`{text}`: the elements of 0x{index:04X} are subs {first} to {last}"
                    )));
                }
                Ok(vec![(index, sub)])
            }
            (Target::Element(index, first, last), None) => Err(LiveError::Usage(format!(
                "`{text}` is an array element type: give its sub, e.g. `{base}<{first}>` \
                 (subs {first} to {last} of 0x{index:04X})"
            ))),
            (_, Some(_)) => Err(LiveError::Usage(format!(
                "`{base}` is not an array element type; `<N>` does not apply"
            ))),
        }
    }

    fn whole(&self, index: u16) -> Option<Vec<(u16, u8)>> {
        let object = self.device.objects.get(&index)?;
        let subs: Vec<(u16, u8)> = object.entries.keys().map(|&s| (index, s)).collect();
        (!subs.is_empty()).then_some(subs)
    }

    fn missing_key(&self, index: u16, sub: Option<u8>) -> LiveError {
        let name = self.device.source.clone();
        match (self.device.objects.get(&index), sub) {
            (Some(object), Some(sub)) => {
                let subs: Vec<String> = object.entries.keys().map(u8::to_string).collect();
                LiveError::Usage(format!(
                    "0x{index:04X} {} has no sub {sub} in {name} (its subs: {})",
                    object.name,
                    subs.join(", ")
                ))
            }
            _ => LiveError::Usage(format!(
                "{name} has no object 0x{index:04X} (use a key without --od for raw access)"
            )),
        }
    }

    fn unknown(&self, text: &str) -> LiveError {
        let wanted = normalize(text);
        // Per name: its score, and the spelling closest to what was typed.
        let mut scored: Vec<(f64, &str, Target)> = Vec::new();
        for (key, list) in self.names() {
            let score = strsim::jaro_winkler(&wanted, key);
            if score < 0.85 {
                continue;
            }
            let best = list.iter().max_by(|a, b| {
                strsim::jaro_winkler(text, &a.0)
                    .total_cmp(&strsim::jaro_winkler(text, &b.0))
                    .then(b.0.cmp(&a.0))
            });
            if let Some((name, target)) = best {
                scored.push((score, name, *target));
            }
        }
        scored.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(b.1)));
        let mut shown: Vec<(&str, Target)> = Vec::new();
        for (_, name, target) in scored {
            if !shown.iter().any(|(_, t)| *t == target) && shown.len() < 3 {
                shown.push((name, target));
            }
        }
        let mut message = format!("no object named `{text}` in {}", self.device.source);
        if !shown.is_empty() {
            let list: Vec<String> = shown
                .iter()
                .map(|(n, t)| format!("`{n}` ({})", target_key(*t)))
                .collect();
            message.push_str(&format!("; did you mean {}?", list.join(" or ")));
        }
        LiveError::Usage(message)
    }

    /// `0x1018.1 Identity.Vendor-ID` (or `0x6041 Statusword` for a VAR).
    pub fn label(&self, index: u16, sub: u8) -> String {
        match self.device.objects.get(&index) {
            Some(object) if matches!(object.kind, ObjectKind::Var | ObjectKind::Domain) => {
                format!("{} {}", key(index, sub), object.name)
            }
            Some(object) => match object.entries.get(&sub) {
                Some(entry) => format!("{} {}.{}", key(index, sub), object.name, entry.name),
                None => key(index, sub),
            },
            None => key(index, sub),
        }
    }
}

/// `0x6041` for sub 0, `0x1018.1` otherwise (the api listing's keys).
pub fn key(index: u16, sub: u8) -> String {
    if sub == 0 {
        format!("0x{index:04X}")
    } else {
        format!("0x{index:04X}.{sub}")
    }
}

fn target_key(t: Target) -> String {
    match t {
        Target::Object(i) => format!("0x{i:04X}"),
        Target::Entry(i, s) => key(i, s),
        Target::Element(i, a, b) => format!("0x{i:04X}.{a}..{b}"),
    }
}

/// `Name<3>` or `Name[3]` → (`Name`, Some(3)).
fn split_element(text: &str) -> (&str, Option<u8>) {
    for (open, close) in [('<', '>'), ('[', ']')] {
        if let Some(body) = text.strip_suffix(close)
            && let Some((base, n)) = body.rsplit_once(open)
            && let Some(n) = parse_int(n).and_then(|n| u8::try_from(n).ok())
        {
            return (base, Some(n));
        }
    }
    (text, None)
}

/// A key: `0x6041`, `0x6041.1` (decimal sub, as the api listing),
/// `0x6041.0x01`, `0x6041:1`, `0x6041sub1` (hex sub, as EDS sections).
/// `Ok(None)` when `text` is not a key (a name).
pub fn parse_key(text: &str) -> Result<Option<(u16, Option<u8>)>, LiveError> {
    let t = text.trim();
    let Some(rest) = t.strip_prefix("0x").or_else(|| t.strip_prefix("0X")) else {
        return Ok(None);
    };
    let bad = || {
        LiveError::Usage(format!(
            "`{text}` is not an object key (0x6041, 0x1018.1, 0x1018sub1 or 0x1018:1)"
        ))
    };
    let lower = rest.to_ascii_lowercase();
    let (index, sub) = if let Some((i, s)) = lower.split_once("sub") {
        let sub = u8::from_str_radix(s, 16).map_err(|_| bad())?;
        (i.to_string(), Some(sub))
    } else if let Some((i, s)) = lower.split_once(['.', ':']) {
        let sub = parse_int(s)
            .and_then(|v| u8::try_from(v).ok())
            .ok_or_else(bad)?;
        (i.to_string(), Some(sub))
    } else {
        (lower, None)
    };
    if index.is_empty() || index.len() > 4 {
        return Err(bad());
    }
    let index = u16::from_str_radix(&index, 16).map_err(|_| bad())?;
    Ok(Some((index, sub)))
}

/// The Rust names of `eds2rust api`'s listing: entries (`od::Statusword`
/// → 0x6041.0), ARRAY/RECORD modules (`od::identity` → 0x1018) and array
/// element types (`od::…::PreDefinedErrorField<SUB>` → 0x1003.1..254),
/// each with and without the `od::` prefix and by its last segment.
fn rust_names(listing: &str) -> Vec<(String, Target)> {
    const ACCESS: [&str; 6] = ["ro", "wo", "rw", "rwr", "rww", "const"];
    let mut out = Vec::new();
    for line in listing.lines() {
        let cols: Vec<&str> = line.split('\t').collect();
        let (Some(path), Some(key), Some(third)) = (cols.first(), cols.get(1), cols.get(2)) else {
            continue;
        };
        let Some(path) = path.strip_prefix("od::") else {
            continue;
        };
        let Some(hex) = key.strip_prefix("0x") else {
            continue;
        };
        let (index, subs) = hex.split_once('.').unwrap_or((hex, "0"));
        let Ok(index) = u16::from_str_radix(index, 16) else {
            continue;
        };
        let target = if *third == "module array" || *third == "module record" {
            Target::Object(index)
        } else if cols.len() == 6 && ACCESS.contains(&cols[3]) {
            match subs.split_once("..") {
                Some((a, b)) => match (a.parse(), b.parse()) {
                    (Ok(a), Ok(b)) => Target::Element(index, a, b),
                    _ => continue,
                },
                None => match subs.parse() {
                    Ok(s) => Target::Entry(index, s),
                    Err(_) => continue,
                },
            }
        } else {
            continue;
        };
        let path = path.strip_suffix("<SUB>").unwrap_or(path);
        out.push((path.to_string(), target));
        if let Some((_, last)) = path.rsplit_once("::") {
            out.push((last.to_string(), target));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn zimmer() -> Od {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../eds/zimmer_acs.yaml");
        Od::load(&path).unwrap()
    }

    #[test]
    fn keys() {
        assert_eq!(parse_key("0x6041").unwrap(), Some((0x6041, None)));
        assert_eq!(parse_key("0x1018.1").unwrap(), Some((0x1018, Some(1))));
        assert_eq!(parse_key("0x1018sub1").unwrap(), Some((0x1018, Some(1))));
        assert_eq!(parse_key("0x1003sub0A").unwrap(), Some((0x1003, Some(10))));
        assert_eq!(parse_key("0x1018:4").unwrap(), Some((0x1018, Some(4))));
        assert_eq!(parse_key("Statusword").unwrap(), None);
        assert!(parse_key("0x1018.300").is_err());
        assert!(parse_key("0x12345").is_err());
    }

    #[test]
    fn names_rust_names_and_suggestions() {
        let od = zimmer();
        assert_eq!(od.resolve("Statusword").unwrap(), [(0x6041, 0)]);
        assert_eq!(od.resolve("statusword").unwrap(), [(0x6041, 0)]);
        assert_eq!(od.resolve("identity::VendorId").unwrap(), [(0x1018, 1)]);
        assert_eq!(od.resolve("0x1018").unwrap().len(), 4);
        assert_eq!(
            od.resolve("pre_defined_error_field::PreDefinedErrorField<2>")
                .unwrap(),
            [(0x1003, 2)]
        );
        let LiveError::Usage(message) = od.resolve("Statuswrod").unwrap_err() else {
            panic!("not a usage error");
        };
        assert!(message.contains("did you mean `Statusword`"), "{message}");
        assert!(od.resolve("0x1018.9").is_err());
    }
}
