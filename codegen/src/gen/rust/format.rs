//! Formatting the generated file a part at a time.
//!
//! prettyplease formats a parsed file, and a parsed file (syn's syntax tree)
//! takes several times the memory of its tokens: a device of a million
//! entries parsed whole took gigabytes. So each module is formatted as its
//! shell (attributes, `mod name {`, the runtime import) followed by each
//! group of items formatted on its own inside a module of the same depth,
//! and the long `OBJECTS` table a chunk of rows at a time. prettyplease puts
//! items of a module one after the other and starts every element of a
//! broken array on its own line, so the text is the same as the whole file
//! formatted at once (a test in this module checks it).

use proc_macro2::TokenStream;
use quote::quote;

use super::objects::Table;

/// Rows of `OBJECTS` formatted together; a table of at most this many rows
/// is formatted whole.
const CHUNK: usize = 256;

/// Formats tokens that make a whole file.
pub(super) fn file(tokens: TokenStream) -> syn::Result<String> {
    Ok(prettyplease::unparse(&syn::parse2::<syn::File>(tokens)?))
}

/// The formatted items as they stand directly inside a top-level module.
pub(super) fn in_module(items: TokenStream) -> syn::Result<String> {
    let text = file(quote!(mod m { #items }))?;
    Ok(text
        .strip_prefix("mod m {\n")
        .and_then(|t| t.strip_suffix("}\n"))
        .unwrap_or_default()
        .to_string())
}

/// Appends to `out` the top-level module `shell` (its attributes and the
/// items it starts with) with `body` (items formatted by [`in_module`])
/// and then `table` added at its end.
pub(super) fn module(
    out: &mut String,
    shell: TokenStream,
    body: &str,
    table: Option<Table>,
) -> syn::Result<()> {
    let head = file(shell)?;
    let Some(head) = head.strip_suffix("}\n") else {
        return Err(syn::Error::new(
            proc_macro2::Span::call_site(),
            "a module shell without items",
        ));
    };
    out.push_str(head);
    out.push_str(body);
    if let Some(table) = table {
        out.push_str(&objects(table)?);
    }
    out.push_str("}\n");
    Ok(())
}

/// The formatted `OBJECTS` constant inside a top-level module.
fn objects(table: Table) -> syn::Result<String> {
    let whole = || {
        let rows: Vec<TokenStream> = table.rows().collect();
        in_module(table.item(&rows))
    };
    if table.len <= CHUNK {
        return whole();
    }
    // So many rows never fit on one line: every row starts a line, as next
    // to a row longer than any line. The constant is formatted around such
    // a row, and each chunk of rows followed by it; the lines of the rows
    // are what comes before it.
    let long = proc_macro2::Literal::string(&"x".repeat(120));
    let long = quote!(#long);
    let marker = format!("{long},\n");
    let split = |text: &str| -> Option<(usize, usize)> {
        let at = text.find(&marker)?;
        let line_start = text[..at].rfind('\n')? + 1;
        text[line_start..at]
            .bytes()
            .all(|b| b == b' ')
            .then_some((line_start, at + marker.len()))
    };
    let shell = in_module(table.item(std::slice::from_ref(&long)))?;
    let Some((head_end, tail_start)) = split(&shell) else {
        return whole();
    };
    let head = &shell[..head_end];
    let mut text = head.to_string();
    let mut rows = table.rows().peekable();
    while rows.peek().is_some() {
        let mut chunk: Vec<TokenStream> = rows.by_ref().take(CHUNK).collect();
        chunk.push(long.clone());
        let part = in_module(table.item(&chunk))?;
        match split(&part) {
            Some((end, _)) if part.starts_with(head) => text.push_str(&part[head.len()..end]),
            // Not the layout this relies on: format the table whole.
            _ => return whole(),
        }
    }
    text.push_str(&shell[tail_start..]);
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A device whose `OBJECTS` has rows of every length around the line
    /// width (some fit on one line, some break), defaults and limits.
    fn device() -> crate::ir::Device {
        let mut eds = String::from("[DeviceInfo]\nVendorName=v\n");
        for i in 0..700u32 {
            let name = "n".repeat((i % 97) as usize + 1);
            eds.push_str(&format!(
                "[{:04X}]\nParameterName={name}\nObjectType=0x7\nDataType=0x0007\nAccessType=rw\n",
                0x2000 + i
            ));
            if i % 3 == 0 {
                eds.push_str(&format!("DefaultValue={i}\nLowLimit=0\nHighLimit=100000\n"));
            }
        }
        eds.push_str("[3000]\nParameterName=Array\nObjectType=0x8\nDataType=0x0007\nAccessType=ro\nCompactSubObj=254\n");
        let loaded = crate::eds::read_bytes("t.eds", eds.as_bytes(), &Default::default());
        loaded.device.expect("a device")
    }

    #[test]
    fn objects_in_chunks_is_the_table_formatted_whole() {
        let device = device();
        let table = super::super::objects::emit(&device, &quote!(rt));
        assert!(table.len > 3 * CHUNK);
        let rows: Vec<TokenStream> = table.rows().collect();
        let whole = in_module(table.item(&rows)).unwrap();
        assert!(
            whole
                .lines()
                .any(|l| l.trim_start().starts_with(".with_default"))
        );
        assert_eq!(objects(table).unwrap(), whole);
    }
}
