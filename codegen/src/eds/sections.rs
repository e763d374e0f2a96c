//! What a section name means in CiA 306.

/// The role of one `[section]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SectionKind<'a> {
    /// `[1018]`
    Object(u16),
    /// `[1018sub2]`: the sub number as written (one or more hex digits), read
    /// by [`hex_sub`] or, for an object written in decimal, [`decimal_subs`].
    Sub(u16, &'a str),
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
pub fn classify(name: &str) -> SectionKind<'_> {
    let name = name.trim();
    if let Some(index) = hex4(name) {
        return SectionKind::Object(index);
    }
    if name.len() > 4
        && name.is_char_boundary(4)
        && let Some(index) = hex4(&name[..4])
    {
        let rest = &name[4..];
        if let Some(sub) = strip_prefix_no_case(rest, "sub") {
            if !sub.is_empty() && sub.bytes().all(|b| b.is_ascii_hexdigit()) {
                return SectionKind::Sub(index, sub);
            }
            return SectionKind::Unknown;
        }
        if rest.eq_ignore_ascii_case("name") {
            return SectionKind::CompactNames(index);
        }
        if rest.eq_ignore_ascii_case("value") {
            return SectionKind::CompactValues(index);
        }
    }
    let is_tool =
        strip_prefix_no_case(name, "tool").is_some_and(|n| n.bytes().all(|b| b.is_ascii_digit()));
    // Modular devices (CiA 306 §4.6): [M1ModuleInfo], [M1FixedObjects], [M2SubExt6000] …
    let is_module = strip_prefix_no_case(name, "m")
        .is_some_and(|r| r.starts_with(|c: char| c.is_ascii_digit()));
    if KNOWN.iter().any(|k| k.eq_ignore_ascii_case(name)) || is_tool || is_module {
        SectionKind::Known
    } else {
        SectionKind::Unknown
    }
}

/// `s` without `prefix` (lowercase ASCII), matched without regard to case.
fn strip_prefix_no_case<'s>(s: &'s str, prefix: &str) -> Option<&'s str> {
    s.get(..prefix.len())
        .filter(|head| head.eq_ignore_ascii_case(prefix))
        .map(|_| &s[prefix.len()..])
}

/// The sub-index of a sub-section name by CiA 306: 1 or 2 hex digits.
pub fn hex_sub(digits: &str) -> Option<u8> {
    if digits.len() <= 2 {
        u8::from_str_radix(digits, 16).ok()
    } else {
        None
    }
}

/// The sub-indices of one object's sub-section names (`digits`, in section
/// order) read as decimal, when the names are decimal beyond doubt: some
/// name read as hex is above 0xFF, no name has a hex letter, and the
/// decimal readings are distinct sub-indices (0–255) as many as `sub_number`
/// (the object's SubNumber). `None` keeps the hex rule.
pub fn decimal_subs(digits: &[&str], sub_number: Option<i128>) -> Option<Vec<u8>> {
    let above_ff = |d: &str| u32::from_str_radix(d, 16).map_or(true, |v| v > 0xFF);
    if !digits.iter().any(|d| above_ff(d))
        || digits
            .iter()
            .any(|d| !d.bytes().all(|b| b.is_ascii_digit()))
    {
        return None;
    }
    let subs: Vec<u8> = digits
        .iter()
        .map(|d| d.parse::<u8>().ok())
        .collect::<Option<_>>()?;
    let distinct: std::collections::BTreeSet<u8> = subs.iter().copied().collect();
    let count = i128::try_from(subs.len()).ok()?;
    (distinct.len() == subs.len() && sub_number == Some(count)).then_some(subs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names() {
        assert_eq!(classify("1018"), SectionKind::Object(0x1018));
        assert_eq!(classify("1a00SUB1"), SectionKind::Sub(0x1A00, "1"));
        assert_eq!(classify("1016sub1F"), SectionKind::Sub(0x1016, "1F"));
        assert_eq!(classify(" 2000sub100"), SectionKind::Sub(0x2000, "100"));
        assert_eq!(classify("1016Name"), SectionKind::CompactNames(0x1016));
        assert_eq!(classify("1016value"), SectionKind::CompactValues(0x1016));
        assert_eq!(classify("DeviceInfo"), SectionKind::Known);
        assert_eq!(classify("Tool3"), SectionKind::Known);
        assert_eq!(classify("10G0"), SectionKind::Unknown);
        assert_eq!(classify("10000"), SectionKind::Unknown);
        assert_eq!(classify("1000sub"), SectionKind::Unknown);
        assert_eq!(classify("1000sub1g"), SectionKind::Unknown);
    }

    #[test]
    fn sub_numbers() {
        assert_eq!(hex_sub("1F"), Some(0x1F));
        assert_eq!(hex_sub("100"), None);
        assert_eq!(hex_sub("001"), None, "CiA 306: 1 or 2 digits");
        let decimal: Vec<String> = (0..=100).map(|s| s.to_string()).collect();
        let decimal: Vec<&str> = decimal.iter().map(String::as_str).collect();
        assert_eq!(decimal_subs(&decimal, Some(101)), Some((0..=100).collect()));
        assert_eq!(decimal_subs(&decimal, Some(100)), None, "SubNumber");
        assert_eq!(decimal_subs(&decimal, None), None, "no SubNumber");
        assert_eq!(decimal_subs(&["0", "1", "A", "100"], Some(4)), None);
        assert_eq!(decimal_subs(&["0", "1", "2"], Some(3)), None, "all fit hex");
        assert_eq!(decimal_subs(&["0", "256"], Some(2)), None, "above 255");
        assert_eq!(decimal_subs(&["10", "010", "100"], Some(3)), None);
        assert_eq!(
            decimal_subs(&["0", "1", "99999999999"], Some(3)),
            None,
            "too long for either"
        );
        assert_eq!(decimal_subs(&["000", "255"], Some(2)), Some(vec![0, 255]));
    }
}
