//! IR → Rust source: the typed, zero-cost driver of one device.
//!
//! The output is one file meant for `include!` into a module of the user's
//! choosing, and needs only `core` plus the runtime's `od` module:
//! - identity constants at the top (vendor id, product code, default node id
//!   and bit rate, ...);
//! - `od`: one zero-sized type per entry (`entries`) with its value type
//!   (`values` chooses it: an enum (`enums`), a bit-field struct
//!   (`bits`), a scaled newtype (`scaled`) or a primitive (`prim`));
//! - `errors`: one enum per device error table (`errors`);
//! - `pdo`: one struct per default PDO (`pdo`).
//!
//! Every kind of generated type derives one list of traits (`derives`).
//! Every identifier comes from the naming table (`naming`); source text
//! reaches the output only inside doc strings (`docs`). Items are emitted
//! in index order and the file is formatted by prettyplease, so the same IR
//! always gives the same bytes.

#[cfg(feature = "api")]
mod api;
mod arrays;
mod bits;
mod derives;
mod docs;
mod entries;
mod enums;
mod errors;
mod format;
mod hazards;
pub(crate) mod naming;
#[cfg(feature = "network")]
pub(crate) mod network;
#[cfg(feature = "network")]
mod network_plan;
mod objects;
mod od_module;
pub(crate) mod od_plan;
pub(crate) mod pdo;
mod prim;
mod scaled;
mod value_parts;
mod values;

#[cfg(feature = "api")]
pub use api::{ApiListing, api_listing};

use proc_macro2::TokenStream;
use quote::quote;

use crate::diag::{Diagnostic, Diagnostics, Location, Severity};
use crate::ir::{Device, Value};

/// The name generated modules import the runtime crate as
/// (`use ::eds2rust_runtime as rt;`); no generated module takes it.
pub(crate) const RUNTIME_ALIAS: &str = "rt";

/// How to generate.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Options {
    /// The path of the runtime crate in generated code (`::eds2rust_runtime`
    /// by default; a crate that re-exports the runtime gives its own path).
    pub runtime_path: String,
    /// Turn every warning into an error.
    pub strict: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            runtime_path: "::eds2rust_runtime".into(),
            strict: false,
        }
    }
}

/// What a valid runtime path looks like, for messages.
pub const RUNTIME_PATH_HELP: &str = "a runtime path is the path of a crate or module as a `use` \
declaration takes it: identifiers joined by `::`, optionally starting with `::`, `crate::`, \
`self::` or `super::`, and ending in an identifier (the default is `::eds2rust_runtime`)";

/// The runtime path as tokens, or what is wrong with it ("is empty", "has
/// `Self`, which ..."): `generate` and the command line check it before
/// anything is generated, so that a wrong path is named as such and not
/// reported as invalid generated code.
pub fn check_runtime_path(path: &str) -> Result<TokenStream, String> {
    if path.trim().is_empty() {
        return Err("is empty".into());
    }
    if path != path.trim() {
        return Err("has spaces around it".into());
    }
    let body = path.strip_prefix("::").unwrap_or(path);
    let segments: Vec<&str> = body.split("::").collect();
    let last = segments.len() - 1;
    for (i, segment) in segments.iter().enumerate() {
        if segment.is_empty() {
            return Err(if i == last {
                "ends in `::`; it must end in an identifier".into()
            } else {
                "has an empty segment (`::::` or a leading `::` twice)".into()
            });
        }
        let prefix = !path.starts_with("::")
            && segments[..i].iter().all(|s| matches!(*s, "self" | "super"))
            && (i == 0 || *segment == "super");
        match *segment {
            "crate" | "self" if i == 0 && prefix && i != last => continue,
            "super" if prefix && i != last => continue,
            "crate" | "self" | "super" => {
                return Err(format!(
                    "has `{segment}` where only a crate or module name may stand"
                ));
            }
            "Self" => {
                return Err("has `Self`, which names a type, not a crate or module".into());
            }
            _ => {}
        }
        if syn::parse_str::<syn::Ident>(segment).is_err() {
            return Err(format!(
                "has `{}`, which is not a Rust identifier",
                crate::text::terminal_line(segment)
            ));
        }
    }
    match syn::parse_str::<syn::Path>(path) {
        Ok(parsed) => Ok(quote!(#parsed)),
        Err(err) => Err(format!("is not a Rust path: {err}")),
    }
}

/// Generated source and the warnings found on the way.
#[derive(Debug, Clone)]
pub struct Output {
    /// The formatted Rust source, starting with an `@generated` comment. It
    /// is meant for `include!` (no inner attributes).
    pub code: String,
    pub warnings: Diagnostics,
}

/// The first line of every generated file.
pub const HEADER: &str = "// @generated by eds2rust from";

/// Generates the Rust source of one device. Errors (and, with
/// `options.strict`, warnings) are returned together.
pub fn generate(device: &Device, options: &Options) -> Result<Output, Diagnostics> {
    generate_parts(device, None, options).map(|(output, _)| output)
}

/// The Rust source of one node of a network: `device`'s object dictionary
/// exactly as [`generate`] makes it, and in `pdo` the PDOs of `configured`
/// (the device with the network's mappings and communication values as
/// configured values, see `network::configured`) instead of the defaults.
/// Also says which PDO structs were made.
#[cfg(feature = "network")]
pub(crate) fn generate_node(
    device: &Device,
    configured: &Device,
    options: &Options,
) -> Result<(Output, Vec<pdo::Emitted>), Diagnostics> {
    generate_parts(device, Some(configured), options)
}

fn generate_parts(
    device: &Device,
    configured: Option<&Device>,
    options: &Options,
) -> Result<(Output, Vec<pdo::Emitted>), Diagnostics> {
    let mut diags = Diagnostics::new();
    let runtime: TokenStream = match check_runtime_path(&options.runtime_path) {
        Ok(path) => path,
        Err(problem) => {
            diags.push(Diagnostic {
                severity: Severity::Error,
                code: "gen::runtime-path",
                file: device.source.clone(),
                location: Location::default(),
                message: format!(
                    "runtime path `{}` {problem}",
                    crate::text::terminal_line(&options.runtime_path)
                ),
                notes: vec![RUNTIME_PATH_HELP.into()],
            });
            return Err(diags);
        }
    };
    // Generated code names the runtime by a short alias, imported once at
    // the top of each module.
    let rt = naming::ident(RUNTIME_ALIAS);
    let rt = quote!(#rt);
    let use_runtime = quote!(use #runtime as #rt;);
    hazards::warn(device, &mut diags);
    let error_plans = errors::plan(device, &mut diags);
    let mut cx = entries::Ctx {
        device,
        rt: &rt,
        errors: &error_plans,
        diags: &mut diags,
    };
    // Each object's items are formatted as they are made and their tokens
    // dropped: the tokens of a whole device take many times its text.
    let mut od_body = String::new();
    let mut format_error = None;
    let infos = od_module::emit(&mut cx, &mut |items| {
        if format_error.is_none() {
            match format::in_module(items) {
                Ok(text) => od_body.push_str(&text),
                Err(err) => format_error = Some(err),
            }
        }
    });
    let error_items = errors::emit(device, &error_plans, &rt, &mut diags);
    let (pdo_items, emitted) = match configured {
        None => pdo::emit(device, &infos, pdo::Source::Defaults, &rt, &mut diags),
        Some(configured) => pdo::emit(configured, &infos, pdo::Source::Network, &rt, &mut diags),
    };
    let object_table = objects::emit(device, &rt);
    let identity = identity_items(device);

    let od_shell = quote! {
        #[doc = " The object dictionary: one zero-sized type per entry (see the runtime's `od::Entry`)."]
        pub mod od {
            #use_runtime
        }
    };
    let mut errors = None;
    if !device.error_tables.is_empty() {
        errors = Some(quote! {
            #[doc = " Device error tables as enums."]
            pub mod errors {
                #use_runtime
                #error_items
            }
        });
    }
    let mut pdo = None;
    if !pdo_items.is_empty() {
        let doc = match configured {
            None => " Default PDOs: fixed layouts with `encode`/`decode`.",
            Some(_) => " The PDOs the network configures: fixed layouts with `encode`/`decode`.",
        };
        pdo = Some(quote! {
            #[doc = #doc]
            pub mod pdo {
                #use_runtime
                #pdo_items
            }
        });
    }
    // A part at a time: the syntax tree of a whole file takes many times
    // the memory of its tokens (format.rs).
    let formatted = (|| -> syn::Result<String> {
        if let Some(err) = format_error {
            return Err(err);
        }
        let mut code = format::file(identity)?;
        format::module(&mut code, od_shell, &od_body, Some(object_table))?;
        for module in errors.into_iter().chain(pdo) {
            code.push_str(&format::file(module)?);
        }
        Ok(code)
    })();
    let code = match formatted {
        Ok(code) => code,
        Err(err) => {
            diags.push(Diagnostic {
                severity: Severity::Error,
                code: "gen::internal",
                file: device.source.clone(),
                location: Location::default(),
                message: format!("the generator produced invalid Rust (a bug in eds2rust): {err}"),
                notes: Vec::new(),
            });
            return Err(diags);
        }
    };
    if options.strict {
        diags.make_strict();
    }
    if diags.has_errors() {
        diags.sort();
        return Err(diags);
    }
    diags.sort();
    let source = device.source.replace(['\n', '\r'], " ");
    // Text from the input reaches the code in doc comments (prettyplease
    // writes `#[doc]` strings as `///` lines) and in this header: control
    // and bidi characters there become `\u{...}` escapes, so that rustc's
    // deny-by-default lints (`text_direction_codepoint_in_comment`) and
    // terminals never see them. String literals are escaped by quote already.
    let code = format!("{HEADER} {source}; do not edit.\n\n{code}");
    Ok((
        Output {
            code: crate::text::code(&code).into_owned(),
            warnings: diags,
        },
        emitted,
    ))
}

/// Constants of the device's identity and network defaults.
fn identity_items(device: &Device) -> TokenStream {
    let id = &device.identity;
    let mut out = TokenStream::new();
    let mut text_const = |name: &str, doc: &str, value: &Option<String>| {
        if let Some(value) = value {
            let ident = naming::ident(name);
            out.extend(quote!(#[doc = #doc] pub const #ident: &str = #value;));
        }
    };
    text_const("VENDOR_NAME", " Vendor name.", &id.vendor_name);
    text_const("PRODUCT_NAME", " Product name.", &id.product_name);
    text_const("ORDER_CODE", " Order code.", &id.order_code);
    let mut number_const = |name: &str, doc: &str, value: Option<u32>| {
        if let Some(value) = value {
            let ident = naming::ident(name);
            let lit = prim::hex(u128::from(value));
            out.extend(quote!(#[doc = #doc] pub const #ident: u32 = #lit;));
        }
    };
    number_const("VENDOR_ID", " Vendor id (0x1018 sub 1).", id.vendor_number);
    number_const(
        "PRODUCT_CODE",
        " Product code (0x1018 sub 2).",
        id.product_number,
    );
    number_const(
        "REVISION_NUMBER",
        " Revision number (0x1018 sub 3).",
        id.revision_number,
    );
    let device_type = device
        .objects
        .get(&0x1000)
        .and_then(|o| o.entries.get(&0))
        .and_then(|e| e.default.as_ref())
        .filter(|l| !l.plus_node_id)
        .and_then(|l| match l.value {
            Value::Integer(v) => u32::try_from(v).ok(),
            _ => None,
        });
    number_const(
        "DEVICE_TYPE",
        " Device type (0x1000), as delivered.",
        device_type,
    );
    let node_id = device
        .network
        .node_id
        .or(device.commissioning.as_ref().and_then(|c| c.node_id))
        .filter(|n| (1..=127).contains(n));
    if let Some(node_id) = node_id {
        let node_id = proc_macro2::Literal::u8_unsuffixed(node_id);
        out.extend(quote! {
            #[doc = " Node id as delivered."]
            pub const DEFAULT_NODE_ID: u8 = #node_id;
        });
    }
    let bit_rate = device
        .network
        .bit_rate
        .or(device.commissioning.as_ref().and_then(|c| c.baud_rate));
    if let Some(bit_rate) = bit_rate {
        let bit_rate = proc_macro2::Literal::u32_unsuffixed(bit_rate);
        out.extend(quote! {
            #[doc = " Bit rate as delivered, kbit/s."]
            pub const DEFAULT_BIT_RATE_KBIT: u32 = #bit_rate;
        });
    }
    let rates = &device.capabilities.baud_rates;
    if !rates.is_empty() {
        let rates = rates
            .iter()
            .map(|r| proc_macro2::Literal::u32_unsuffixed(*r));
        out.extend(quote! {
            #[doc = " Supported bit rates, kbit/s."]
            pub const BIT_RATES_KBIT: &[u32] = &[#(#rates),*];
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::check_runtime_path;

    #[test]
    fn runtime_paths() {
        for ok in [
            "::eds2rust_runtime",
            "my::rt",
            "crate::rt",
            "self::rt",
            "super::super::rt",
            "r#type",
        ] {
            assert!(check_runtime_path(ok).is_ok(), "{ok}");
        }
        for (bad, why) in [
            ("Self", "names a type"),
            ("1abc", "not a Rust identifier"),
            ("foo::", "ends in `::`"),
            ("a b", "not a Rust identifier"),
            ("", "is empty"),
            ("crate", "only a crate or module name"),
            ("a::super", "only a crate or module name"),
            ("::crate::x", "only a crate or module name"),
            (" x", "spaces"),
            ("a::::b", "empty segment"),
        ] {
            let problem = check_runtime_path(bad).unwrap_err();
            assert!(problem.contains(why), "{bad:?}: {problem}");
        }
    }
}
