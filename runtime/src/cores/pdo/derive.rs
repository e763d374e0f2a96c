//! What `#[derive(Pdo)]` expands to besides the codec of [`super::layout`]:
//! the compile-time checks of a custom mapping, as trait bounds whose
//! messages say what is wrong, and the constant arithmetic of its layout.
//! Not an API of its own: only the derive's expansion names these items.

use crate::od::standard::PdoCobId;
use crate::od::{DataType, Entry};

/// A condition computed at compile time, as a type: the checks below are
/// implemented only for `Check<true>`.
pub struct Check<const OK: bool>;

/// The field's mapping ends beyond bit 64.
#[diagnostic::on_unimplemented(
    message = "this field does not fit: a PDO holds at most 64 bits (8 bytes) in all",
    label = "the mapping is longer than 64 bits from this field on",
    note = "map fewer or shorter entries (`bits = N`), or split them over two PDOs"
)]
pub trait FitsInPdo {}
impl FitsInPdo for Check<true> {}

/// `bits = N` is longer than the entry's data type.
#[diagnostic::on_unimplemented(
    message = "`bits` is longer than the entry's data type",
    label = "more bits than the object has",
    note = "`bits = N` maps the low N bits of an entry; N is at most the size of its data type"
)]
pub trait BitsFit {}
impl BitsFit for Check<true> {}

/// The same object (index and sub-index) is mapped twice.
#[diagnostic::on_unimplemented(
    message = "this object is already mapped by an earlier field of this PDO",
    label = "mapped twice",
    note = "a PDO maps each object once; remove one of the fields"
)]
pub trait MappedOnce {}
impl MappedOnce for Check<true> {}

/// The entry has no fixed size (a string or DOMAIN).
#[diagnostic::on_unimplemented(
    message = "this object has no fixed size and cannot be mapped into a PDO",
    label = "a string or DOMAIN entry"
)]
pub trait FixedSize {}
impl FixedSize for Check<true> {}

/// The field's type is `V`, the value type of the entry `E` it maps.
#[diagnostic::on_unimplemented(
    message = "the field's type `{Self}` is not `{V}`, the value type of `{E}`",
    label = "expected `{V}`",
    note = "give the field the entry's value type: `{V}` (or write `<{E} as Entry>::Value`)"
)]
pub trait ValueTypeOf<E, V> {}
impl<E, V> ValueTypeOf<E, V> for V {}

/// Compiles only when `T` is `E`'s value type.
pub const fn value_of<E: Entry, T: ValueTypeOf<E, E::Value>>() {}

/// The width the struct's layout table states for a field (its Rust type's
/// size) is the mapped one.
#[diagnostic::on_unimplemented(
    message = "this entry is narrower than the field's type: write its width with `bits = N`",
    label = "the entry maps fewer bits than this type holds",
    note = "an INTEGER24 in an `i32` (or a 40-, 48- or 56-bit type in a 64-bit one) is mapped with `bits = 24` (40, 48, 56), so that the layout the struct documents is the one on the bus"
)]
pub trait WidthAsDocumented {}
impl WidthAsDocumented for Check<true> {}

/// Compiles only when the check holds.
pub const fn width_as_documented<C: WidthAsDocumented>() {}

/// Compiles only when the check holds.
pub const fn fits<C: FitsInPdo>() {}
/// Compiles only when the check holds.
pub const fn bits_fit<C: BitsFit>() {}
/// Compiles only when the check holds.
pub const fn mapped_once<C: MappedOnce>() {}
/// Compiles only when the check holds.
pub const fn fixed_size<C: FixedSize>() {}

/// The number of bits of a data type (0 without a fixed size).
pub const fn type_bits(data_type: DataType) -> u32 {
    match data_type.size() {
        Some(bytes) => bytes as u32 * 8,
        None => 0,
    }
}

/// The offsets of fields of `widths`, one after the other from bit 0.
pub const fn offsets<const N: usize>(widths: [u32; N]) -> [u32; N] {
    let mut out = [0u32; N];
    let mut at = 0u32;
    let mut i = 0;
    while i < N {
        out[i] = at;
        at = at.saturating_add(widths[i]);
        i += 1;
    }
    out
}

/// The sum of `widths`.
pub const fn total<const N: usize>(widths: [u32; N]) -> u32 {
    let mut sum = 0u32;
    let mut i = 0;
    while i < N {
        sum = sum.saturating_add(widths[i]);
        i += 1;
    }
    sum
}

/// Whether field `i` (`offset`, `width`) is not the one that makes the
/// mapping longer than 64 bits: every field before it fits.
pub const fn fits_at(offset: u32, width: u32) -> bool {
    !(offset <= 64 && offset.saturating_add(width) > 64)
}

/// `key(index, sub)` of a mapped entry, [`NO_KEY`] for a gap.
pub const fn key(index: u16, subindex: u8) -> u32 {
    (index as u32) << 8 | subindex as u32
}

/// The key of a gap, which may repeat.
pub const NO_KEY: u32 = u32::MAX;

/// Whether `keys[i]` is not among `keys[..i]` (gaps aside).
pub const fn first_of_its_key<const N: usize>(keys: [u32; N], i: usize) -> bool {
    if keys[i] == NO_KEY {
        return true;
    }
    let mut j = 0;
    while j < i {
        if keys[j] == keys[i] {
            return false;
        }
        j += 1;
    }
    true
}

/// How many mapping entries a field takes: 1 for an entry, the dummies of
/// [`super::layout::dummy_entries`] for a gap of `bits`.
pub const fn entry_count(gap: Option<u32>) -> usize {
    match gap {
        None => 1,
        Some(bits) => {
            let mut out = [0u32; 64];
            super::layout::dummy_entries(bits, &mut out)
        }
    }
}

/// Appends a field's mapping entries to `out` at `n`; returns the new `n`.
pub const fn push_entries<const N: usize>(
    out: &mut [u32; N],
    mut n: usize,
    entry: Option<(u16, u8)>,
    width: u32,
) -> usize {
    match entry {
        Some((index, subindex)) => {
            out[n] = super::layout::mapping_entry(index, subindex, width);
            n + 1
        }
        None => {
            let mut dummies = [0u32; 64];
            let count = super::layout::dummy_entries(width, &mut dummies);
            let mut k = 0;
            while k < count {
                out[n] = dummies[k];
                n += 1;
                k += 1;
            }
            n
        }
    }
}

/// The COB-ID of PDO `number` of the predefined connection set for a node
/// (TPDO1–4: 0x180, 0x280, 0x380, 0x480 + node; RPDO1–4: 0x200, 0x300,
/// 0x400, 0x500 + node); `None` for the PDOs above 4, which have none.
pub const fn predefined_cob_id(tpdo: bool, number: u16, node: u8) -> Option<PdoCobId> {
    if number == 0 || number > 4 {
        return None;
    }
    let base = if tpdo { 0x080 } else { 0x100 };
    Some(PdoCobId::from_raw(
        base + 0x100 * number as u32 + node as u32,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_arithmetic() {
        assert_eq!(offsets([16, 32, 4, 4]), [0, 16, 48, 52]);
        assert_eq!(total([16, 32, 4, 4]), 56);
        assert!(fits_at(48, 16) && !fits_at(60, 8) && !fits_at(64, 1) && fits_at(72, 8));
        let keys = [key(0x6041, 0), NO_KEY, NO_KEY, key(0x6041, 0)];
        assert!(first_of_its_key(keys, 1) && first_of_its_key(keys, 2));
        assert!(!first_of_its_key(keys, 3));
        assert_eq!(entry_count(Some(12)), 5); // UNSIGNED8 and 4 BOOLEAN dummies
        let mut out = [0u32; 3];
        let n = push_entries(&mut out, 0, Some((0x6041, 0)), 16);
        let n = push_entries(&mut out, n, None, 9);
        assert_eq!((n, out), (3, [0x6041_0010, 0x0005_0008, 0x0001_0001]));
        assert_eq!(predefined_cob_id(true, 2, 5), Some(PdoCobId(0x285)));
        assert_eq!(predefined_cob_id(false, 1, 5), Some(PdoCobId(0x205)));
        assert_eq!(predefined_cob_id(false, 5, 5), None);
    }
}
