//! A DCF as sections of keys, written as CiA 306 text.

/// Sections in the order they are written, each with its keys in order.
#[derive(Debug, Default)]
pub(super) struct Ini {
    sections: Vec<(String, Vec<(String, String)>)>,
}

impl Ini {
    /// Opens a new section; the keys that follow go into it.
    pub(super) fn section(&mut self, name: impl Into<String>) -> &mut Self {
        self.sections.push((name.into(), Vec::new()));
        self
    }

    /// Adds `key=value` to the section opened last.
    pub(super) fn key(&mut self, key: impl Into<String>, value: impl ToString) -> &mut Self {
        if let Some((_, keys)) = self.sections.last_mut() {
            keys.push((key.into(), value.to_string()));
        }
        self
    }

    /// The text: one `[section]` line, its `key=value` lines, a blank line.
    pub(super) fn render(&self) -> String {
        let mut out = String::new();
        for (n, (name, keys)) in self.sections.iter().enumerate() {
            if n > 0 {
                out.push('\n');
            }
            out.push('[');
            out.push_str(name);
            out.push_str("]\n");
            for (key, value) in keys {
                out.push_str(key);
                out.push('=');
                out.push_str(value);
                out.push('\n');
            }
        }
        out
    }
}

/// `0x` and `digits` upper-case hex digits.
pub(super) fn hex(value: impl Into<u64>, digits: usize) -> String {
    format!("0x{:0digits$X}", value.into())
}

/// Sub 0's name in a record (the PDO parameters write it lower-case).
pub(super) const HIGHEST: &str = "Highest sub-index supported";
pub(super) const HIGHEST_PDO: &str = "highest sub-index supported";

/// A 0x1F22/0x1F58-like array of DOMAIN files per node id 1–127.
pub(super) fn files_array(
    ini: &mut Ini,
    index: u32,
    name: &str,
    sub_name: &str,
    files: &[(u8, &str)],
) {
    ini.section(format!("{index:04X}"))
        .key("SubNumber", 128)
        .key("ParameterName", name)
        .key("ObjectType", "0x08");
    sub(
        ini,
        index,
        0,
        HIGHEST,
        0x0005,
        "const",
        Some("127".to_string()),
    );
    for node_id in 1..=127u8 {
        sub(
            ini,
            index,
            u32::from(node_id),
            &format!("{sub_name} {node_id}"),
            0x000F,
            "ro",
            None,
        );
        for (_, file) in files.iter().filter(|(n, _)| *n == node_id) {
            ini.key("UploadFile", file);
        }
    }
}

pub(super) fn var<'a>(
    ini: &'a mut Ini,
    index: u32,
    name: &str,
    data_type: u32,
    access: &str,
    default: Option<String>,
) -> &'a mut Ini {
    ini.section(format!("{index:04X}"));
    entry_keys(ini, name, data_type, access, default)
}

pub(super) fn entry_keys<'a>(
    ini: &'a mut Ini,
    name: &str,
    data_type: u32,
    access: &str,
    default: Option<String>,
) -> &'a mut Ini {
    ini.key("ParameterName", name)
        .key("DataType", hex(data_type, 4))
        .key("AccessType", access);
    if let Some(default) = default {
        ini.key("DefaultValue", default);
    }
    ini
}

/// A RECORD's head and its sub 0 (`highest` its value).
pub(super) fn record(ini: &mut Ini, index: u32, name: &str, highest: u32, sub0: &str) {
    ini.section(format!("{index:04X}"))
        .key("SubNumber", highest + 1)
        .key("ParameterName", name)
        .key("ObjectType", "0x09");
    sub(
        ini,
        index,
        0,
        sub0,
        0x0005,
        "const",
        Some(highest.to_string()),
    );
}

pub(super) fn sub<'a>(
    ini: &'a mut Ini,
    index: u32,
    sub: u32,
    name: &str,
    data_type: u32,
    access: &str,
    default: Option<String>,
) -> &'a mut Ini {
    ini.section(format!("{index:04X}sub{sub:X}"));
    entry_keys(ini, name, data_type, access, default)
}

/// A compact ARRAY of `len` entries.
pub(super) fn array(
    ini: &mut Ini,
    index: u32,
    name: &str,
    data_type: u32,
    access: &str,
    len: usize,
) {
    ini.section(format!("{index:04X}"))
        .key("ParameterName", name)
        .key("ObjectType", "0x08")
        .key("DataType", hex(data_type, 4))
        .key("AccessType", access)
        .key("CompactSubObj", len);
}

/// The `[xxxxValue]` section of a compact array.
pub(super) fn values(ini: &mut Ini, index: u32, entries: Vec<(String, String)>) {
    ini.section(format!("{index:04X}Value"))
        .key("NrOfEntries", entries.len());
    for (key, value) in entries {
        ini.key(key, value);
    }
}
