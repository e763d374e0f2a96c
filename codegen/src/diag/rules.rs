//! Every diagnostic rule the readers, the generator and the builder report,
//! by its stable code: what `allow`/`deny` may name, and what "did you
//! mean" suggests from.

/// One rule: its code and what it is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Rule {
    pub code: &'static str,
    pub summary: &'static str,
}

const fn rule(code: &'static str, summary: &'static str) -> Rule {
    Rule { code, summary }
}

/// Every rule, sorted by code.
pub const RULES: &[Rule] = &[
    rule(
        "build::device-name",
        "a device name that is not a unique snake_case identifier",
    ),
    rule(
        "build::no-device",
        "no device could be generated from an input",
    ),
    rule(
        "build::out-dir",
        "no output directory (OUT_DIR unset, no out_dir given)",
    ),
    rule(
        "build::overlay-not-yaml",
        "an overlay that is not a YAML table",
    ),
    rule(
        "build::overlay-without-device",
        "an overlay given before any device",
    ),
    rule(
        "build::unknown-rule",
        "allow/deny of a rule code that does not exist",
    ),
    rule("build::write", "an output file that could not be written"),
    rule(
        "eds::bad-access",
        "an AccessType that CiA 306 does not define",
    ),
    rule("eds::bad-data-type", "a DataType that is not a number"),
    rule("eds::bad-index", "an object index that cannot be used"),
    rule("eds::bad-number", "a number that cannot be read"),
    rule(
        "eds::bad-object-type",
        "an ObjectType that CiA 306 does not define",
    ),
    rule(
        "eds::bad-pdo-mapping",
        "a PDOMapping value that is not 0 or 1",
    ),
    rule(
        "eds::bad-section-header",
        "a section header that is not `[name]`",
    ),
    rule("eds::bad-value", "a value that does not fit its key"),
    rule(
        "eds::compact-sub-obj",
        "a CompactSubObj object that cannot be expanded as written",
    ),
    rule(
        "eds::decimal-subindex",
        "sub-section names written in decimal, read as decimal",
    ),
    rule("eds::duplicate-key", "a key given twice in one section"),
    rule("eds::duplicate-section", "a section given twice"),
    rule(
        "eds::limits",
        "LowLimit/HighLimit that do not fit the type or each other",
    ),
    rule(
        "eds::line-endings",
        "lines that end with CR alone (old Mac OS)",
    ),
    rule("eds::missing-access", "an entry without AccessType"),
    rule("eds::missing-data-type", "an entry without DataType"),
    rule("eds::missing-name", "an object without ParameterName"),
    rule(
        "eds::missing-object-section",
        "an object listed in an object list without a section",
    ),
    rule("eds::no-objects", "no object sections at all"),
    rule(
        "eds::not-key-value",
        "a line that is neither a section, a key=value nor a comment",
    ),
    rule(
        "eds::not-utf8",
        "text that is not UTF-8, decoded as UTF-16 (after a byte-order mark) or Windows-1252",
    ),
    rule(
        "eds::object-list",
        "an object list (Mandatory/Optional/ManufacturerObjects) that is wrong",
    ),
    rule(
        "eds::orphan-sub",
        "a sub-section whose object has no section",
    ),
    rule("eds::outside-section", "a key before the first section"),
    rule(
        "eds::pdo-mapping",
        "a default PDO mapping entry that does not fit its object",
    ),
    rule(
        "eds::sub-number",
        "SubNumber that does not match the sub-sections",
    ),
    rule(
        "eds::unknown-data-type",
        "a data type code without a definition",
    ),
    rule(
        "eds::unknown-section",
        "a section name that CiA 306 does not define",
    ),
    rule(
        "eds::unlisted-object",
        "an object section not named in any object list",
    ),
    rule(
        "eds::value-out-of-range",
        "a value outside its type or limits",
    ),
    rule(
        "gen::internal",
        "the generator produced invalid Rust (a bug)",
    ),
    rule(
        "gen::name-collision",
        "two entries whose Rust names collide",
    ),
    rule(
        "gen::pdo-skipped",
        "a default PDO that gets no generated struct",
    ),
    rule(
        "gen::runtime-path",
        "a runtime path that is not a crate or module path",
    ),
    rule(
        "gen::rust-name-collision",
        "a `rust_name:` pin equal to another name in its scope",
    ),
    rule(
        "gen::unsafe-text",
        "a name, description or unit with control or bidirectional-text characters",
    ),
    rule(
        "input::feature-off",
        "an input this build cannot read: a YAML table without the `yaml` feature",
    ),
    rule(
        "input::not-a-file",
        "an input that is not a regular file (directory, FIFO, device, /proc)",
    ),
    rule(
        "input::too-large",
        "an input file above the size limit (--max-input-size)",
    ),
    rule(
        "net::auto-cob-id",
        "a PDO with cob_id: auto when no 11-bit COB-ID is left (0x680–0x6DF used up)",
    ),
    rule(
        "net::bad-value",
        "a bus file value of the wrong type or outside its key's range",
    ),
    rule(
        "net::bus-load",
        "an estimated bus load above the limit (--max-bus-load)",
    ),
    rule("net::cob-id-collision", "two nodes sending on one COB-ID"),
    rule(
        "net::cob-id-restricted",
        "a PDO COB-ID in a range CiA 301 restricts",
    ),
    rule(
        "net::device-file",
        "a slave's device file that cannot be read",
    ),
    rule(
        "net::dropped-section",
        "a slave section beside `nodes:`, which ros2_canopen's expansion drops",
    ),
    rule(
        "net::duplicate-key",
        "a key given twice in one map of a bus file (the later wins)",
    ),
    rule(
        "net::duplicate-node",
        "a slave name given twice in a bus file",
    ),
    rule(
        "net::heartbeat-and-guarding",
        "a node with both a heartbeat producer time and node guarding",
    ),
    rule(
        "net::heartbeat-no-producer",
        "a heartbeat consumer of a node that sends none",
    ),
    rule(
        "net::heartbeat-timing",
        "a heartbeat consumer time not above its producer time",
    ),
    rule(
        "net::identity-differs",
        "a bus file's revision or serial number that differs from the device file's",
    ),
    rule(
        "net::missing-key",
        "a key dcfgen needs (`master:`, a slave's `dcf`, an item's `index`)",
    ),
    rule(
        "net::missing-object",
        "a bus file setting whose object the device file lacks (0x1012, 0x1016, 0x1017, 0x100C, 0x100D, 0x1029, 0x1F56, 0x1011)",
    ),
    rule(
        "net::no-node-id",
        "a slave without a node id, left out of the network",
    ),
    rule(
        "net::no-such-pdo",
        "an rpdo/tpdo number the device file has no PDO for",
    ),
    rule(
        "net::node-id",
        "a node id outside 1..=127 in a bus file, or a master without one",
    ),
    rule("net::node-id-collision", "two nodes with one node id"),
    rule(
        "net::not-writable",
        "a configuration write to an entry that is not writable",
    ),
    rule(
        "net::pdo-direction",
        "a bus file's PDO mapping against the entry's access",
    ),
    rule(
        "net::pdo-mapping",
        "a bus file's PDO mapping of an object that is not PDO-mappable",
    ),
    rule(
        "net::pdo-not-generated",
        "a PDO a network configures that gets no generated struct",
    ),
    rule(
        "net::pdo-number",
        "a PDO number outside 1..=512 in a bus file",
    ),
    rule(
        "net::pdo-too-long",
        "a bus file's PDO mapping of more than 64 bits",
    ),
    rule("net::pdo-unconsumed", "a PDO sent that no node reads"),
    rule("net::pdo-unproduced", "a PDO awaited that is never sent"),
    rule(
        "net::sdo-pdo-conflict",
        "an `sdo:` write to a PDO parameter that the PDO sections set or do not see",
    ),
    rule(
        "net::syntax",
        "bus file YAML syntax, not UTF-8, over a limit, or not a map",
    ),
    rule(
        "net::too-large",
        "more than 127 slaves, or `defaults:` expanded beyond the limit",
    ),
    rule(
        "net::truncated",
        "a fraction where dcfgen needs an integer (it cuts it)",
    ),
    rule(
        "net::truthy-text",
        "text where dcfgen reads a boolean (any non-empty text is true)",
    ),
    rule(
        "net::unknown-key",
        "an unknown key in a PDO, mapping or sdo item (dcfgen ignores it)",
    ),
    rule(
        "net::unknown-object",
        "a write or mapping of an object or sub-object the device file lacks",
    ),
    rule("net::unused-defaults", "`defaults:` without `nodes:`"),
    rule(
        "net::value-range",
        "a configuration value that does not fit its entry's data type",
    ),
    rule(
        "table::array-type",
        "an ARRAY whose subs do not share one type",
    ),
    rule(
        "table::bad-access",
        "an access right that is not ro/wo/rw/rwr/rww/const",
    ),
    rule(
        "table::bad-index",
        "an index or sub-index that cannot be used",
    ),
    rule(
        "table::bad-profiles",
        "a `profiles:` value other than `none` or `builtin`",
    ),
    rule("table::bad-range", "a bit range that does not fit"),
    rule(
        "table::bad-scale",
        "a scale factor or offset that cannot be used",
    ),
    rule("table::bad-type", "a data type name that is not known"),
    rule(
        "table::bad-value",
        "a value that cannot be read for its type",
    ),
    rule(
        "table::base",
        "a base EDS that could not be read without errors",
    ),
    rule(
        "table::base-outside",
        "a `base:` outside the project and the allowed directories",
    ),
    rule(
        "table::bit-field",
        "a bit field that does not fit its entry",
    ),
    rule("table::bit-rate", "a bit rate that CiA 301 does not define"),
    rule(
        "table::dangling-reference",
        "a reference to an error table that does not exist",
    ),
    rule("table::duplicate-code", "an error code given twice"),
    rule("table::duplicate-index", "an object index given twice"),
    rule("table::duplicate-name", "a name given twice"),
    rule("table::duplicate-pdo", "a PDO given twice"),
    rule("table::duplicate-sub", "a sub-index given twice"),
    rule("table::format", "a format version that is not known"),
    rule(
        "table::leading-zero",
        "a decimal number with a leading zero",
    ),
    rule(
        "table::limits",
        "limits that do not fit the type or each other",
    ),
    rule(
        "table::misplaced-key",
        "a key that does not belong where it is",
    ),
    rule(
        "table::missing-entry",
        "a reference to an entry that does not exist",
    ),
    rule("table::missing-key", "a key that is needed here"),
    rule("table::named-value", "a named value that cannot be used"),
    rule(
        "table::no-objects",
        "an overlay that deletes every object of its base",
    ),
    rule("table::node-id", "a node id outside 1..=127"),
    rule("table::not-utf8", "a table that is not UTF-8"),
    rule("table::overlap", "bit fields that overlap"),
    rule(
        "table::overlay-base",
        "an overlay given to the builder that names a base of its own",
    ),
    rule(
        "table::overlay-only",
        "delete/modify in a table without a base",
    ),
    rule("table::pattern", "a state pattern that cannot be used"),
    rule(
        "table::pdo-direction",
        "a PDO mapping against the entry's access",
    ),
    rule(
        "table::pdo-dummy",
        "a dummy mapping entry that cannot be used",
    ),
    rule(
        "table::pdo-mapping",
        "a PDO mapping entry that does not fit its object",
    ),
    rule("table::pdo-number", "a PDO number outside 1..=512"),
    rule(
        "table::pdo-parameter",
        "a PDO communication parameter that cannot be used",
    ),
    rule("table::pdo-too-long", "a PDO mapping of more than 64 bits"),
    rule(
        "table::rust-name",
        "a `rust_name:` that is not an identifier of the case needed",
    ),
    rule(
        "table::semantics-type",
        "semantics that do not fit the entry's type",
    ),
    rule(
        "table::syntax",
        "YAML syntax, an unknown key, or a wrong scalar type",
    ),
    rule(
        "table::unknown-rule",
        "a `diagnostics:` entry naming a rule that does not exist",
    ),
    rule(
        "table::value-out-of-range",
        "a value outside its type or limits",
    ),
];

/// Is `code` the code of a rule? (`io`, a file that cannot be read, is
/// not a rule: it cannot be allowed.)
pub fn is_known(code: &str) -> bool {
    RULES.iter().any(|r| r.code == code)
}

/// The rule code closest to `code`, when one is close enough to be what
/// was meant.
pub fn closest(code: &str) -> Option<&'static str> {
    closest_of(code, RULES.iter().map(|r| r.code))
}

/// The candidate closest to `word` by edit distance, when it is close: at
/// most a third of the word's length away (and at least 1). Used for rule
/// codes and for YAML keys.
pub fn closest_of<'a>(
    word: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> Option<&'a str> {
    let limit = (word.chars().count() / 3).max(1);
    candidates
        .into_iter()
        .map(|c| (strsim::levenshtein(word, c), c))
        .filter(|&(distance, _)| distance <= limit)
        .min_by_key(|&(distance, c)| (distance, c))
        .map(|(_, c)| c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sorted_and_unique() {
        for pair in RULES.windows(2) {
            assert!(
                pair[0].code < pair[1].code,
                "{} / {}",
                pair[0].code,
                pair[1].code
            );
        }
    }

    /// Every code the crate's sources report is listed, and every listed
    /// code is reported somewhere.
    #[test]
    fn every_reported_code_is_listed() {
        let mut found = std::collections::BTreeSet::new();
        let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
        collect_codes(&src, &mut found);
        let listed: std::collections::BTreeSet<&str> = RULES.iter().map(|r| r.code).collect();
        let missing: Vec<_> = found
            .iter()
            .filter(|c| !listed.contains(c.as_str()))
            .collect();
        assert!(
            missing.is_empty(),
            "codes reported but not in RULES: {missing:?}"
        );
        let unused: Vec<_> = listed.iter().filter(|c| !found.contains(**c)).collect();
        assert!(
            unused.is_empty(),
            "codes in RULES never reported: {unused:?}"
        );
    }

    fn collect_codes(dir: &std::path::Path, found: &mut std::collections::BTreeSet<String>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                collect_codes(&path, found);
            } else if path.extension().is_some_and(|e| e == "rs")
                && !path.ends_with("diag/rules.rs")
                && !path.ends_with("diag/levels.rs")
            {
                let text = std::fs::read_to_string(&path).unwrap();
                for (start, _) in text.match_indices('"') {
                    let rest = &text[start + 1..];
                    let Some(end) = rest.find('"') else { continue };
                    let word = &rest[..end];
                    let Some((area, name)) = word.split_once("::") else {
                        continue;
                    };
                    let is_code = ["build", "eds", "gen", "input", "net", "table"].contains(&area)
                        && !name.is_empty()
                        && name
                            .bytes()
                            .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'-');
                    if is_code {
                        found.insert(word.to_string());
                    }
                }
            }
        }
    }

    /// docs/diagnostics.md lists exactly these rules, in this order.
    #[test]
    fn the_documented_list_is_this_list() {
        let doc = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/diagnostics.md");
        let text = std::fs::read_to_string(&doc).unwrap();
        let documented: Vec<&str> = text
            .lines()
            .filter_map(|l| l.strip_prefix("| `")?.split('`').next())
            .filter(|code| code.contains("::") && !code.contains('('))
            .collect();
        let listed: Vec<&str> = RULES.iter().map(|r| r.code).collect();
        assert_eq!(documented, listed, "docs/diagnostics.md is out of date");
    }

    #[test]
    fn suggestions() {
        assert_eq!(
            closest("eds::unlisted-objects"),
            Some("eds::unlisted-object")
        );
        assert_eq!(closest("eds:unknown-section"), Some("eds::unknown-section"));
        assert_eq!(closest("nothing-like-it"), None);
        assert_eq!(
            closest_of("semantic", ["semantics", "objects"]),
            Some("semantics")
        );
        assert_eq!(closest_of("xyz", ["semantics", "objects"]), None);
    }
}
