//! The canonical names and built-in meanings of standard objects: CiA 301 and the device
//! profiles, one file per profile, as plain data (index, optional sub, the
//! Rust name and the standard's own name text; and, in `meaning`, the
//! bit fields, states, named values and units the standard fixes). The generator names a
//! standard object by this table, not by the vendor's spelling, so a
//! firmware update that renames `ParameterName` renames nothing in Rust;
//! and every name here is reserved, whether or not the object is present,
//! so that no vendor object takes a standard name.
//!
//! The 0x6000–0x6FFF range means different things in different device
//! profiles; `Profile::of` picks the one a device implements.

use std::collections::HashSet;
use std::sync::OnceLock;

use crate::ir::{DataType, Device, ObjectKind, Value};

mod cia301;
mod cia401;
mod cia402;
mod cia406;
mod meaning;
mod std_meaning;

pub(crate) use meaning::apply;
pub(crate) use std_meaning::RuntimeType;

/// One standard name: an object (`sub: None`) or one of its sub-entries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct StdName {
    pub(crate) index: u16,
    pub(crate) sub: Option<u8>,
    /// The Rust name, in UpperCamelCase (modules use its snake case).
    pub(crate) name: &'static str,
    /// The name as the standard writes it.
    pub(crate) text: &'static str,
}

pub(crate) const fn obj(index: u16, name: &'static str, text: &'static str) -> StdName {
    StdName {
        index,
        sub: None,
        name,
        text,
    }
}

pub(crate) const fn sub(index: u16, sub: u8, name: &'static str, text: &'static str) -> StdName {
    StdName {
        index,
        sub: Some(sub),
        name,
        text,
    }
}

/// A range of numbered objects of the same kind (the PDO and SDO
/// parameters): index `first + k` is named `{prefix}{first_number + k}{suffix}`
/// (`Rpdo1CommunicationParameter`), its subs by `subs`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct NumberedRange {
    pub(crate) first: u16,
    pub(crate) last: u16,
    pub(crate) first_number: u16,
    pub(crate) name: (&'static str, &'static str),
    pub(crate) text: &'static str,
    pub(crate) subs: &'static [(u8, &'static str, &'static str)],
    /// Whether subs 1 and up are one list of like entries (the mapped
    /// objects of a PDO mapping parameter): generated as one indexed type,
    /// like an ARRAY's elements, whatever object code the source gives.
    pub(crate) list: bool,
}

impl NumberedRange {
    fn number(&self, index: u16) -> Option<u16> {
        (self.first..=self.last)
            .contains(&index)
            .then(|| index - self.first + self.first_number)
    }

    fn name_of(&self, number: u16) -> String {
        format!("{}{number}{}", self.name.0, self.name.1)
    }
}

/// A device profile whose objects 0x6000–0x9FFF have standard names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Profile {
    /// CiA 401, generic I/O modules.
    Cia401,
    /// CiA 402, drives and motion control.
    Cia402,
    /// CiA 406, encoders.
    Cia406,
}

impl Profile {
    /// The profile `device` implements: the low 16 bits of the device
    /// type (0x1000, its `ParameterValue` or else its default) when they
    /// are 401, 402 or 406; otherwise, when the device type names no other
    /// profile (0 or absent), CiA 402 when 0x6040 and 0x6041 are what the
    /// profile makes them (UNSIGNED16 variables: a CiA 418 battery has
    /// arrays there); otherwise none.
    pub(crate) fn of(device: &Device) -> Option<Profile> {
        let device_type = device
            .objects
            .get(&0x1000)
            .and_then(|o| o.entries.get(&0))
            .and_then(|e| e.parameter_value.as_ref().or(e.default.as_ref()))
            .and_then(|l| match l.value {
                Value::Integer(v) => Some(v & 0xFFFF),
                _ => None,
            });
        match device_type {
            Some(401) => return Some(Profile::Cia401),
            Some(402) => return Some(Profile::Cia402),
            Some(406) => return Some(Profile::Cia406),
            Some(0) | None => {}
            Some(_) => return None,
        }
        let word = |index: u16| {
            device.objects.get(&index).is_some_and(|o| {
                o.kind == ObjectKind::Var
                    && o.entries
                        .get(&0)
                        .is_some_and(|e| e.data_type == DataType::Unsigned16)
            })
        };
        (word(0x6040) && word(0x6041)).then_some(Profile::Cia402)
    }

    fn objects(self) -> &'static [StdName] {
        match self {
            Profile::Cia401 => cia401::OBJECTS,
            Profile::Cia402 => cia402::OBJECTS,
            Profile::Cia406 => cia406::OBJECTS,
        }
    }
}

/// The canonical names that apply to one device: CiA 301 and its profile.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Canonical {
    pub(crate) profile: Option<Profile>,
}

impl Canonical {
    pub(crate) fn of(device: &Device) -> Canonical {
        Canonical {
            profile: Profile::of(device),
        }
    }

    fn tables(self) -> impl Iterator<Item = &'static StdName> {
        cia301::OBJECTS
            .iter()
            .chain(self.profile.map(Profile::objects).unwrap_or(&[]).iter())
    }

    /// The standard name of object `index`, if it has one.
    pub(crate) fn object(self, index: u16) -> Option<String> {
        if let Some(s) = self.tables().find(|s| s.index == index && s.sub.is_none()) {
            return Some(s.name.to_string());
        }
        cia301::RANGES
            .iter()
            .find_map(|r| r.number(index).map(|n| r.name_of(n)))
    }

    /// How the standard writes the name of object `index` (`Statusword`,
    /// `RPDO communication parameter 3`), if it has a canonical name.
    pub(crate) fn text(self, index: u16) -> Option<String> {
        if let Some(s) = self.tables().find(|s| s.index == index && s.sub.is_none()) {
            return Some(s.text.to_string());
        }
        cia301::RANGES
            .iter()
            .find_map(|r| r.number(index).map(|n| format!("{} {n}", r.text)))
    }

    /// The standard name of sub-entry `sub` of a standard ARRAY or RECORD
    /// object `index`: sub 0 is `HighestSubIndexSupported` unless the
    /// standard names it otherwise.
    pub(crate) fn sub(self, index: u16, sub: u8) -> Option<String> {
        self.object(index)?;
        if let Some(s) = self
            .tables()
            .find(|s| s.index == index && s.sub == Some(sub))
        {
            return Some(s.name.to_string());
        }
        if let Some(r) = cia301::RANGES.iter().find(|r| r.number(index).is_some())
            && let Some(&(_, name, _)) = r.subs.iter().find(|(s, _, _)| *s == sub)
        {
            return Some(name.to_string());
        }
        (sub == 0).then(|| "HighestSubIndexSupported".to_string())
    }

    /// Whether the standard defines subs 1 and up of object `index` as one
    /// list of like entries (see [`NumberedRange::list`]).
    pub(crate) fn is_list(self, index: u16) -> bool {
        cia301::RANGES
            .iter()
            .any(|r| r.list && r.number(index).is_some())
    }

    /// Every object name of CiA 301 and this profile (present or not), in
    /// UpperCamelCase: the names no vendor object may take.
    pub(crate) fn reserved(self) -> &'static HashSet<String> {
        static SETS: [OnceLock<HashSet<String>>; 4] = [const { OnceLock::new() }; 4];
        let slot = match self.profile {
            None => 0,
            Some(Profile::Cia401) => 1,
            Some(Profile::Cia402) => 2,
            Some(Profile::Cia406) => 3,
        };
        SETS[slot].get_or_init(|| {
            let mut set: HashSet<String> = self
                .tables()
                .filter(|s| s.sub.is_none())
                .map(|s| s.name.to_string())
                .collect();
            for r in cia301::RANGES {
                for index in r.first..=r.last {
                    set.insert(r.name_of(r.number(index).expect("in range")));
                }
            }
            set
        })
    }
}

/// Whether `device` is a CiA 402 drive: its device type (0x1000) names
/// profile 402, or names none and the drive's controlword and statusword
/// (0x6040, 0x6041, UNSIGNED16) are there. The rule the generator's
/// built-in meanings follow, for tools that read files at run time.
pub fn is_cia402(device: &Device) -> bool {
    Profile::of(device) == Some(Profile::Cia402)
}

/// How many objects (with a fixed index, not counting sub-entries) and
/// numbered ranges each table names: for the documentation and a test.
#[cfg(test)]
pub(crate) fn coverage() -> [(&'static str, usize); 4] {
    let count = |t: &[StdName]| t.iter().filter(|s| s.sub.is_none()).count();
    [
        ("CiA 301", count(cia301::OBJECTS) + cia301::RANGES.len()),
        ("CiA 401", count(cia401::OBJECTS)),
        ("CiA 402", count(cia402::OBJECTS)),
        ("CiA 406", count(cia406::OBJECTS)),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::r#gen::rust::naming::{Case, sanitize};

    #[test]
    fn names_are_their_own_sanitised_form_and_unique() {
        let all = [
            cia301::OBJECTS,
            cia401::OBJECTS,
            cia402::OBJECTS,
            cia406::OBJECTS,
        ];
        for table in all {
            let mut seen = HashSet::new();
            for s in table {
                assert_eq!(sanitize(s.name, Case::UpperCamel), s.name, "{s:?}");
                assert!(seen.insert((s.index, s.sub)), "twice: {s:?}");
                if s.sub.is_some() {
                    assert!(
                        table.iter().any(|o| o.index == s.index && o.sub.is_none()),
                        "sub of an unnamed object: {s:?}"
                    );
                }
            }
            let objects: Vec<&str> = table
                .iter()
                .filter(|s| s.sub.is_none())
                .map(|s| s.name)
                .collect();
            let unique: HashSet<&&str> = objects.iter().collect();
            assert_eq!(unique.len(), objects.len(), "a name used twice");
        }
        for r in cia301::RANGES {
            let n = r.name_of(r.first_number);
            assert_eq!(sanitize(&n, Case::UpperCamel), n);
            for (_, name, _) in r.subs {
                assert_eq!(sanitize(name, Case::UpperCamel), *name);
            }
        }
    }

    #[test]
    fn numbered_ranges() {
        let c = Canonical { profile: None };
        assert_eq!(
            c.object(0x1400).as_deref(),
            Some("Rpdo1CommunicationParameter")
        );
        assert_eq!(c.object(0x1A03).as_deref(), Some("Tpdo4MappingParameter"));
        assert_eq!(c.object(0x1200).as_deref(), Some("SdoServerParameter"));
        assert_eq!(c.object(0x1201).as_deref(), Some("SdoServer2Parameter"));
        assert_eq!(c.object(0x1280).as_deref(), Some("SdoClient1Parameter"));
        assert_eq!(c.object(0x6041), None);
        assert_eq!(c.sub(0x1800, 1).as_deref(), Some("CobIdUsedByTpdo"));
        assert_eq!(
            c.sub(0x1600, 0).as_deref(),
            Some("HighestSubIndexSupported")
        );
        assert_eq!(c.sub(0x1600, 1), None);
        assert_eq!(c.sub(0x1003, 0).as_deref(), Some("NumberOfErrors"));
        assert_eq!(c.sub(0x2000, 0), None);
        let drive = Canonical {
            profile: Some(Profile::Cia402),
        };
        assert_eq!(drive.object(0x6041).as_deref(), Some("Statusword"));
        assert!(drive.reserved().contains("PositionWindow"));
        assert!(drive.reserved().contains("Tpdo512MappingParameter"));
        assert!(!c.reserved().contains("PositionWindow"));
        for (profile, n) in coverage() {
            assert!(n > 10, "{profile}: {n}");
        }
    }
}
