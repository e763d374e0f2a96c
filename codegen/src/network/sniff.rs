//! Is a file a bus file? A `.yml`/`.yaml` file whose top level has a
//! `master:` key (dcfgen requires that section; a YAML object table never
//! has it). Decided by looking at the top-level keys only, without parsing
//! the YAML, so that `diff` and `api` can choose between a device and a
//! network before reading either.

use std::io::Read;
use std::path::Path;

/// How much of a file is looked at: a bus file's `master:` section comes
/// long before this in any real file.
const SNIFF_LIMIT: u64 = 1 << 20;

/// Whether `path` names a bus file: a `.yml`/`.yaml` file (any case) with a
/// top-level `master:` key in its first MiB. A file that cannot be read is
/// not one (the device reader then reports why).
pub fn is_bus_file(path: &Path) -> bool {
    let yaml = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("yml") || e.eq_ignore_ascii_case("yaml"));
    if !yaml || !path.is_file() {
        return false;
    }
    let mut bytes = Vec::new();
    let read = std::fs::File::open(path).and_then(|f| f.take(SNIFF_LIMIT).read_to_end(&mut bytes));
    read.is_ok() && is_bus_text(&String::from_utf8_lossy(&bytes))
}

/// Whether YAML text has a top-level `master:` key: a line that starts in
/// column 0 (after a byte order mark on the first line), is not a comment,
/// a list item, a directive or a document marker, and whose key (plain or
/// quoted) is `master` followed by a colon that ends the key.
pub fn is_bus_text(text: &str) -> bool {
    let text = text.strip_prefix('\u{FEFF}').unwrap_or(text);
    text.lines()
        .any(|line| top_level_key(line) == Some("master"))
}

/// The key of a top-level `key: ...` line.
fn top_level_key(line: &str) -> Option<&str> {
    let first = line.chars().next()?;
    if first.is_whitespace() || matches!(first, '#' | '-' | '%' | '{' | '[' | '?') {
        return None;
    }
    let (key, rest) = if let Some(quote @ ('"' | '\'')) = line.chars().next() {
        let end = line[1..].find(quote)? + 1;
        (&line[1..end], line[end + 1..].trim_start())
    } else {
        let colon = line.find(':')?;
        (line[..colon].trim_end(), &line[colon..])
    };
    let after = rest.strip_prefix(':')?;
    (after.is_empty() || after.starts_with([' ', '\t'])).then_some(key)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn top_level_master_makes_a_bus_file() {
        assert!(is_bus_text(
            "options:\n  dcf_path: x\nmaster:\n  node_id: 1\n"
        ));
        assert!(is_bus_text("\u{FEFF}# a bus\n---\nmaster: {node_id: 1}\n"));
        assert!(is_bus_text("\"master\" :\n  node_id: 1\n"));
        assert!(is_bus_text("'master':\r\n  node_id: 1\r\n"));
        assert!(is_bus_text("master:\n"));
    }

    #[test]
    fn tables_and_nested_keys_are_not() {
        assert!(!is_bus_text(
            "format: 1\ndevice: { vendor_name: T }\nobjects:\n  - { index: 0x2000 }\n"
        ));
        assert!(!is_bus_text("nodes:\n  master:\n    node_id: 1\n"));
        assert!(!is_bus_text(
            "# master:\n- master: 1\nmasters: 2\nmaster_x: 3\n"
        ));
        assert!(!is_bus_text("master:x\n"));
        assert!(!is_bus_text(""));
    }

    #[test]
    fn files_by_extension_and_content() {
        let dir = std::env::temp_dir().join(format!("eds2rust-sniff-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let write = |name: &str, text: &str| {
            let path = dir.join(name);
            std::fs::write(&path, text).unwrap();
            path
        };
        assert!(is_bus_file(&write("bus.yml", "master:\n  node_id: 1\n")));
        assert!(is_bus_file(&write("bus.YAML", "master:\n  node_id: 1\n")));
        assert!(!is_bus_file(&write("bus.eds", "master:\n  node_id: 1\n")));
        assert!(!is_bus_file(&write("table.yaml", "format: 1\n")));
        assert!(!is_bus_file(&dir.join("absent.yml")));
        assert!(!is_bus_file(&dir));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
