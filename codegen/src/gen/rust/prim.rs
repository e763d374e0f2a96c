//! Primitive Rust types of raw values, and the bit-level conversions the
//! generated code does between them and a PDO's 64-bit word.

use proc_macro2::TokenStream;
use quote::quote;

use crate::ir::{DataType, ValueKind};

/// The Rust type that holds the raw value of a data type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Prim {
    Bool,
    U8,
    U16,
    U32,
    U64,
    I8,
    I16,
    I32,
    I64,
    F32,
    F64,
}

impl Prim {
    /// The raw type of a fixed-size data type (24-bit types in 32 bits, 40- to
    /// 56-bit and TIME types in 64 bits), or `None`.
    pub(crate) fn of(data_type: DataType) -> Option<Prim> {
        if data_type == DataType::Boolean {
            return Some(Prim::Bool);
        }
        match data_type.value_kind()? {
            ValueKind::Integer { signed, bits } => Some(Prim::int(signed, bits)),
            ValueKind::Real { bits: 32 } => Some(Prim::F32),
            ValueKind::Real { .. } => Some(Prim::F64),
            ValueKind::Text | ValueKind::Bytes => None,
        }
    }

    /// The narrowest integer type holding `bits` bits.
    pub(crate) fn int(signed: bool, bits: u32) -> Prim {
        match (signed, bits) {
            (false, 0..=8) => Prim::U8,
            (false, 9..=16) => Prim::U16,
            (false, 17..=32) => Prim::U32,
            (false, _) => Prim::U64,
            (true, 0..=8) => Prim::I8,
            (true, 9..=16) => Prim::I16,
            (true, 17..=32) => Prim::I32,
            (true, _) => Prim::I64,
        }
    }

    pub(crate) fn tokens(self) -> TokenStream {
        match self {
            Prim::Bool => quote!(bool),
            Prim::U8 => quote!(u8),
            Prim::U16 => quote!(u16),
            Prim::U32 => quote!(u32),
            Prim::U64 => quote!(u64),
            Prim::I8 => quote!(i8),
            Prim::I16 => quote!(i16),
            Prim::I32 => quote!(i32),
            Prim::I64 => quote!(i64),
            Prim::F32 => quote!(f32),
            Prim::F64 => quote!(f64),
        }
    }

    pub(crate) fn is_float(self) -> bool {
        matches!(self, Prim::F32 | Prim::F64)
    }

    pub(crate) fn is_signed(self) -> bool {
        matches!(self, Prim::I8 | Prim::I16 | Prim::I32 | Prim::I64)
    }

    pub(crate) fn is_integer(self) -> bool {
        !self.is_float() && self != Prim::Bool
    }

    /// The unsigned type of the same width (bit operations on signed raws).
    pub(crate) fn unsigned(self) -> Prim {
        match self {
            Prim::I8 => Prim::U8,
            Prim::I16 => Prim::U16,
            Prim::I32 => Prim::U32,
            Prim::I64 => Prim::U64,
            other => other,
        }
    }

    /// The inclusive range of an integer type.
    pub(crate) fn range(self) -> (i128, i128) {
        match self {
            Prim::Bool => (0, 1),
            Prim::U8 => (0, u8::MAX.into()),
            Prim::U16 => (0, u16::MAX.into()),
            Prim::U32 => (0, u32::MAX.into()),
            Prim::U64 | Prim::F64 => (0, u64::MAX.into()),
            Prim::I8 => (i8::MIN.into(), i8::MAX.into()),
            Prim::I16 => (i16::MIN.into(), i16::MAX.into()),
            Prim::I32 | Prim::F32 => (i32::MIN.into(), i32::MAX.into()),
            Prim::I64 => (i64::MIN.into(), i64::MAX.into()),
        }
    }

    /// An integer literal of this type: hex for unsigned values from 10 up,
    /// decimal otherwise.
    pub(crate) fn lit(self, value: i128) -> TokenStream {
        if value < 0 {
            let magnitude = proc_macro2::Literal::u128_unsuffixed(value.unsigned_abs());
            quote!(-#magnitude)
        } else if !self.is_signed() && value >= 10 {
            hex(value as u128)
        } else {
            let lit = proc_macro2::Literal::u128_unsuffixed(value as u128);
            quote!(#lit)
        }
    }
}

/// `0x...` with `_` every four digits from eight digits up, as rustfmt and
/// clippy like them.
pub(crate) fn hex(value: u128) -> TokenStream {
    let digits = format!("{value:X}");
    let digits = if digits.len() > 4 && digits.len() % 2 == 1 {
        format!("0{digits}")
    } else {
        digits
    };
    let text = if digits.len() >= 8 {
        let mut grouped = String::new();
        let first = digits.len() % 4;
        if first > 0 {
            grouped.push_str(&digits[..first]);
        }
        for (i, chunk) in digits.as_bytes()[first..].chunks(4).enumerate() {
            if i > 0 || first > 0 {
                grouped.push('_');
            }
            grouped.push_str(std::str::from_utf8(chunk).unwrap_or(""));
        }
        format!("0x{grouped}")
    } else {
        format!("0x{digits}")
    };
    text.parse().unwrap_or_default()
}

/// An expression turning a raw value into its bit pattern as `u64`
/// (unmasked: signed values are sign-extended).
pub(crate) fn to_bits(prim: Prim, raw: TokenStream) -> TokenStream {
    match prim {
        Prim::Bool | Prim::U8 | Prim::U16 | Prim::U32 => quote!(u64::from(#raw)),
        Prim::U64 => raw,
        Prim::F32 => quote!(u64::from(#raw.to_bits())),
        Prim::F64 => quote!(#raw.to_bits()),
        Prim::I8 | Prim::I16 | Prim::I32 | Prim::I64 => quote!(#raw as u64),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hex_literals() {
        assert_eq!(hex(0xFB00).to_string(), "0xFB00");
        assert_eq!(hex(0x1_0000).to_string(), "0x010000");
        assert_eq!(hex(0x6000_0000).to_string(), "0x6000_0000");
        assert_eq!(hex(0x1_2345_6789).to_string(), "0x01_2345_6789");
    }
}
