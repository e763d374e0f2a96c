//! What a section name means in CiA 306.

/// The role of one `[section]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SectionKind {
    /// `[1018]`
    Object(u16),
    /// `[1018sub2]`
    Sub(u16, u8),
    /// `[1016Name]`: names of compact sub-objects.
    CompactNames(u16),
    /// `[1016Value]`: DCF values of compact sub-objects.
    CompactValues(u16),
    /// A section CiA 306 defines that is not an object (FileInfo, DummyUsage, …).
    Known,
    /// Anything else.
    Unknown,
}

/// Sections defined by CiA 306 (or written by common tools) that are not objects.
const KNOWN: &[&str] = &[
    "fileinfo",
    "deviceinfo",
    "dummyusage",
    "comments",
    "mandatoryobjects",
    "optionalobjects",
    "manufacturerobjects",
    "devicecomissioning",
    "devicecommissioning",
    "dynamicchannels",
    "supportedmodules",
    "connectedmodules",
    "tools",
];

fn hex4(s: &str) -> Option<u16> {
    if s.len() == 4 && s.bytes().all(|b| b.is_ascii_hexdigit()) {
        u16::from_str_radix(s, 16).ok()
    } else {
        None
    }
}

/// Classifies a section name (as written; case does not matter).
pub fn classify(name: &str) -> SectionKind {
    let lower = name.trim().to_ascii_lowercase();
    if let Some(index) = hex4(&lower) {
        return SectionKind::Object(index);
    }
    if lower.len() > 4
        && lower.is_char_boundary(4)
        && let Some(index) = hex4(&lower[..4])
    {
        let rest = &lower[4..];
        if let Some(sub) = rest.strip_prefix("sub") {
            if !sub.is_empty() && sub.len() <= 2 && sub.bytes().all(|b| b.is_ascii_hexdigit()) {
                return SectionKind::Sub(index, u8::from_str_radix(sub, 16).unwrap_or(0));
            }
            return SectionKind::Unknown;
        }
        match rest {
            "name" => return SectionKind::CompactNames(index),
            "value" => return SectionKind::CompactValues(index),
            _ => {}
        }
    }
    let is_tool = lower
        .strip_prefix("tool")
        .is_some_and(|n| n.bytes().all(|b| b.is_ascii_digit()));
    // Modular devices (CiA 306 §4.6): [M1ModuleInfo], [M1FixedObjects], [M2SubExt6000] …
    let is_module = lower
        .strip_prefix('m')
        .is_some_and(|r| r.starts_with(|c: char| c.is_ascii_digit()));
    if KNOWN.contains(&lower.as_str()) || is_tool || is_module {
        SectionKind::Known
    } else {
        SectionKind::Unknown
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names() {
        assert_eq!(classify("1018"), SectionKind::Object(0x1018));
        assert_eq!(classify("1a00SUB1"), SectionKind::Sub(0x1A00, 1));
        assert_eq!(classify("1016sub1F"), SectionKind::Sub(0x1016, 0x1F));
        assert_eq!(classify("1016Name"), SectionKind::CompactNames(0x1016));
        assert_eq!(classify("1016value"), SectionKind::CompactValues(0x1016));
        assert_eq!(classify("DeviceInfo"), SectionKind::Known);
        assert_eq!(classify("Tool3"), SectionKind::Known);
        assert_eq!(classify("10G0"), SectionKind::Unknown);
        assert_eq!(classify("10000"), SectionKind::Unknown);
        assert_eq!(classify("1000sub123"), SectionKind::Unknown);
    }
}
