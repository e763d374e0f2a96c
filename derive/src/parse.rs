//! The input of `#[derive(Pdo)]`: the struct and its `#[pdo(..)]`
//! attributes, with every syntactic mistake an error at its place.

use proc_macro2::Span;
use syn::spanned::Spanned;
use syn::{Data, DeriveInput, Error, Fields, Ident, LitInt, Path, Result, Type};

/// A PDO's direction, from the device's point of view.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Direction {
    Tpdo,
    Rpdo,
}

pub(crate) struct Pdo<'a> {
    pub(crate) ident: &'a Ident,
    pub(crate) direction: Direction,
    pub(crate) number: u16,
    /// The path of the runtime crate (`::eds2rust_runtime` unless
    /// `runtime = path` says otherwise).
    pub(crate) runtime: Path,
    pub(crate) fields: Vec<Field<'a>>,
}

pub(crate) struct Field<'a> {
    pub(crate) ident: &'a Ident,
    pub(crate) ty: &'a Type,
    pub(crate) kind: FieldKind,
    /// Where errors about the entry point: its path (the attribute for a
    /// gap).
    pub(crate) span: Span,
}

pub(crate) enum FieldKind {
    /// A mapped entry, with `bits = N` when the mapping is shorter than its
    /// type.
    Entry { path: Path, bits: Option<u32> },
    /// A gap of dummy entries.
    Gap(u32),
}

pub(crate) fn pdo(input: &DeriveInput) -> Result<Pdo<'_>> {
    if !input.generics.params.is_empty() {
        return Err(Error::new(
            input.generics.span(),
            "a PDO struct cannot be generic: its layout is fixed by the entries it names",
        ));
    }
    let named = match &input.data {
        Data::Struct(s) => match &s.fields {
            Fields::Named(named) => named,
            Fields::Unnamed(_) => {
                return Err(Error::new(
                    s.fields.span(),
                    "a PDO struct needs named fields, one per mapped entry: \
                     `#[pdo(entry = od::Statusword)] pub status: u16`",
                ));
            }
            Fields::Unit => {
                return Err(Error::new(
                    input.ident.span(),
                    "a PDO struct needs at least one field: a unit struct maps nothing",
                ));
            }
        },
        Data::Enum(e) => {
            return Err(Error::new(
                e.enum_token.span,
                "`#[derive(Pdo)]` is for structs: an enum has no fixed layout",
            ));
        }
        Data::Union(u) => {
            return Err(Error::new(
                u.union_token.span,
                "`#[derive(Pdo)]` is for structs, not unions",
            ));
        }
    };
    if named.named.is_empty() {
        return Err(Error::new(
            input.ident.span(),
            "a PDO struct needs at least one field: an empty struct maps nothing",
        ));
    }
    let (direction, number, runtime) = struct_attr(input)?;
    let mut fields = Vec::new();
    let mut errors: Option<Error> = None;
    for f in &named.named {
        match field(f) {
            Ok(field) => fields.push(field),
            Err(e) => match &mut errors {
                Some(all) => all.combine(e),
                None => errors = Some(e),
            },
        }
    }
    if let Some(e) = errors {
        return Err(e);
    }
    Ok(Pdo {
        ident: &input.ident,
        direction,
        number,
        runtime,
        fields,
    })
}

/// `#[pdo(tpdo = N)]` or `#[pdo(rpdo = N)]`, and `runtime = path`.
fn struct_attr(input: &DeriveInput) -> Result<(Direction, u16, Path)> {
    let mut direction: Option<(Direction, u16)> = None;
    let mut runtime: Option<Path> = None;
    let mut seen = false;
    for attr in input.attrs.iter().filter(|a| a.path().is_ident("pdo")) {
        seen = true;
        attr.parse_nested_meta(|meta| {
            let dir = if meta.path.is_ident("tpdo") {
                Some(Direction::Tpdo)
            } else if meta.path.is_ident("rpdo") {
                Some(Direction::Rpdo)
            } else {
                None
            };
            if let Some(dir) = dir {
                let lit: LitInt = meta.value()?.parse()?;
                let n: u16 = lit
                    .base10_parse()
                    .map_err(|_| Error::new(lit.span(), "a PDO number is 1 to 512"))?;
                if !(1..=512).contains(&n) {
                    return Err(Error::new(lit.span(), "a PDO number is 1 to 512"));
                }
                if direction.is_some() {
                    return Err(meta.error(
                        "the direction is given twice: a PDO is either `tpdo = N` or `rpdo = N`",
                    ));
                }
                direction = Some((dir, n));
                Ok(())
            } else if meta.path.is_ident("runtime") {
                runtime = Some(meta.value()?.parse()?);
                Ok(())
            } else {
                Err(meta.error(
                    "unknown key: the struct's `#[pdo(..)]` takes `tpdo = N` or `rpdo = N`, \
                     and `runtime = path` (the runtime crate's path, when it is not \
                     `eds2rust_runtime`)",
                ))
            }
        })?;
    }
    let Some((direction, number)) = direction else {
        let why = if seen {
            "the PDO's direction and number are missing: add `tpdo = N` or `rpdo = N`"
        } else {
            "add `#[pdo(tpdo = N)]` or `#[pdo(rpdo = N)]` to say which PDO this is"
        };
        return Err(Error::new(input.ident.span(), why));
    };
    let runtime = runtime.unwrap_or_else(|| syn::parse_quote!(::eds2rust_runtime));
    Ok((direction, number, runtime))
}

/// A field's `#[pdo(entry = path[, bits = N])]` or `#[pdo(gap = N)]`.
fn field(f: &syn::Field) -> Result<Field<'_>> {
    let ident = f.ident.as_ref().expect("named fields have names");
    let attrs: Vec<&syn::Attribute> = f
        .attrs
        .iter()
        .filter(|a| a.path().is_ident("pdo"))
        .collect();
    let Some(attr) = attrs.first() else {
        return Err(Error::new(
            ident.span(),
            "every field maps an entry, `#[pdo(entry = od::Statusword)]`, \
             or is a gap, `#[pdo(gap = 8)]`",
        ));
    };
    if let Some(second) = attrs.get(1) {
        return Err(Error::new(
            second.span(),
            "one `#[pdo(..)]` per field: put its keys in one attribute",
        ));
    }
    let mut entry: Option<Path> = None;
    let mut bits: Option<u32> = None;
    let mut gap: Option<u32> = None;
    let width = |lit: &LitInt, what: &str, max: u32| -> Result<u32> {
        let n: u32 = lit.base10_parse().map_err(|_| {
            Error::new(
                lit.span(),
                format!("`{what}` is a number of bits, 1 to {max}"),
            )
        })?;
        if n == 0 || n > max {
            return Err(Error::new(
                lit.span(),
                format!("`{what} = {n}`: a field has 1 to {max} bits"),
            ));
        }
        Ok(n)
    };
    attr.parse_nested_meta(|meta| {
        if meta.path.is_ident("entry") {
            entry = Some(meta.value()?.parse()?);
            Ok(())
        } else if meta.path.is_ident("bits") {
            let lit: LitInt = meta.value()?.parse()?;
            bits = Some(width(&lit, "bits", 64)?);
            Ok(())
        } else if meta.path.is_ident("gap") {
            let lit: LitInt = meta.value()?.parse()?;
            gap = Some(width(&lit, "gap", 64)?);
            Ok(())
        } else {
            Err(meta.error(
                "unknown key: a field's `#[pdo(..)]` takes `entry = path` (with `bits = N` \
                 for a mapping shorter than the entry's type) or `gap = N`",
            ))
        }
    })?;
    // Errors about the entry point at its path; others at the attribute.
    let span = entry.as_ref().map_or_else(|| attr.span(), |p| p.span());
    let kind = match (entry, bits, gap) {
        (Some(path), bits, None) => FieldKind::Entry { path, bits },
        (None, None, Some(n)) => {
            if !is_unit(&f.ty) {
                return Err(Error::new(
                    f.ty.span(),
                    "a gap holds no value: give it the type `()`",
                ));
            }
            FieldKind::Gap(n)
        }
        (None, Some(_), None) => {
            return Err(Error::new(
                span,
                "`bits = N` needs the entry: `entry = path, bits = N`",
            ));
        }
        (Some(_), _, Some(_)) | (None, Some(_), Some(_)) => {
            return Err(Error::new(
                span,
                "a field is an entry or a gap, not both: `entry = path` or `gap = N`",
            ));
        }
        (None, None, None) => {
            return Err(Error::new(
                span,
                "say what the field maps: `entry = path` or `gap = N`",
            ));
        }
    };
    Ok(Field {
        ident,
        ty: &f.ty,
        kind,
        span,
    })
}

fn is_unit(ty: &Type) -> bool {
    matches!(ty, Type::Tuple(t) if t.elems.is_empty())
}
