//! Every generated type with `from_raw`/`to_raw` (enums of meanings, value
//! newtypes, bit-field structs, scaled numbers) of the seed devices reads
//! back every value it makes: `to_raw(from_raw(r)) == r` and
//! `from_raw(to_raw(x)) == x` for `x = from_raw(r)`, over every raw value of
//! 8 and 16 bits and a spread of wider ones; and every enum variant is the
//! meaning of some raw value (no variant that cannot be read back).
//! The list of types is written by build.rs from the generated code.

use std::collections::BTreeSet;
use std::fmt::Debug;

/// A raw type of generated values, with the values to try.
trait Raw: Copy + Debug {
    fn samples() -> Vec<Self>;
    /// Whether every value of the type is in `samples`.
    const EXHAUSTIVE: bool;
    fn same(self, other: Self) -> bool;
}

macro_rules! exhaustive {
    ($($t:ty),*) => {$(
        impl Raw for $t {
            fn samples() -> Vec<Self> {
                (<$t>::MIN..=<$t>::MAX).collect()
            }
            const EXHAUSTIVE: bool = true;
            fn same(self, other: Self) -> bool {
                self == other
            }
        }
    )*};
}
exhaustive!(u8, i8, u16, i16);

/// Edges, powers of two and their neighbours, and a fixed pseudo-random spread.
fn spread(bits: u32) -> Vec<u64> {
    let mask = if bits == 64 {
        u64::MAX
    } else {
        (1u64 << bits) - 1
    };
    let mut out: BTreeSet<u64> = BTreeSet::new();
    for shift in 0..bits {
        let p = 1u64 << shift;
        for v in [p, p - 1, p + 1, mask - p + 1] {
            out.insert(v & mask);
        }
    }
    out.extend([0, mask, mask / 2, mask / 2 + 1]);
    let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
    for _ in 0..20_000 {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        out.insert(x & mask);
    }
    out.into_iter().collect()
}

macro_rules! sampled {
    ($($t:ty => $bits:expr, $from:expr, $eq:expr);* $(;)?) => {$(
        impl Raw for $t {
            fn samples() -> Vec<Self> {
                spread($bits).into_iter().map($from).collect()
            }
            const EXHAUSTIVE: bool = false;
            fn same(self, other: Self) -> bool {
                $eq(self, other)
            }
        }
    )*};
}
sampled! {
    u32 => 32, |v| v as u32, |a, b| a == b;
    i32 => 32, |v| v as u32 as i32, |a, b| a == b;
    u64 => 64, |v| v, |a, b| a == b;
    i64 => 64, |v| v as i64, |a, b| a == b;
    f32 => 32, |v| f32::from_bits(v as u32), |a: f32, b: f32| a.to_bits() == b.to_bits();
    f64 => 64, f64::from_bits, |a: f64, b: f64| a.to_bits() == b.to_bits();
}

/// Counts of what was checked.
#[derive(Default)]
struct Checked {
    types: usize,
    enums: usize,
}

fn check<R: Raw, T: Copy + PartialEq + Debug>(
    checked: &mut Checked,
    name: &str,
    from_raw: fn(R) -> T,
    to_raw: fn(T) -> R,
    variants: Option<&[&str]>,
) {
    checked.types += 1;
    let mut seen: BTreeSet<String> = BTreeSet::new();
    for raw in R::samples() {
        let value = from_raw(raw);
        let back = to_raw(value);
        assert!(
            back.same(raw),
            "{name}: from_raw({raw:?}) = {value:?}, whose to_raw is {back:?}"
        );
        assert_eq!(
            from_raw(back),
            value,
            "{name}: {value:?} does not read back as itself"
        );
        if variants.is_some() {
            let debug = format!("{value:?}");
            let end = debug.find(['(', ' ', '{']).unwrap_or(debug.len());
            seen.insert(debug[..end].to_string());
        }
    }
    if let (Some(variants), true) = (variants, R::EXHAUSTIVE) {
        checked.enums += 1;
        for variant in variants {
            assert!(
                seen.contains(*variant),
                "{name}::{variant} is the meaning of no raw value"
            );
        }
    }
}

#[test]
fn every_generated_value_reads_back_as_itself() {
    let mut checked = Checked::default();
    include!(concat!(env!("OUT_DIR"), "/roundtrip_cases.rs"));
    // The seeds have well over a hundred such types: an empty list is a
    // broken build script, not a pass.
    assert!(checked.types > 100, "only {} types checked", checked.types);
    assert!(
        checked.enums > 20,
        "only {} enums checked in full",
        checked.enums
    );
}
