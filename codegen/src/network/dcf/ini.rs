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
