//! The meanings the standards fix, as data: the types of the profile
//! tables (`MEANINGS` in `cia301.rs`, `cia402.rs`) and their `const`
//! builders. [`super::meaning`] applies them to a device.

/// The meaning the standard gives one entry, or the same entry of a range
/// of objects (`index..=last`, the PDO parameters) and of a range of subs.
#[derive(Debug, Clone, Copy)]
pub(crate) struct StdMeaning {
    pub(crate) index: u16,
    pub(crate) last: u16,
    pub(crate) subs: (u8, u8),
    pub(crate) unit: Option<&'static str>,
    /// Physical value of one raw step in `unit` (`0.1` for 100 µs in ms).
    pub(crate) scale: Option<f64>,
    pub(crate) bits: &'static [StdBit],
    pub(crate) patterns: &'static [StdPattern],
    pub(crate) values: Option<StdValues>,
    /// The runtime type the generated value type converts to and from.
    pub(crate) runtime: Option<RuntimeType>,
}

/// A type of `eds2rust_runtime` that stands for an entry's value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct RuntimeType {
    /// The path below the runtime crate, `cia402::Statusword`.
    pub(crate) path: &'static str,
    /// How it holds the raw value: a tuple struct `T(pub raw)`, or through
    /// `From<raw>` and `From<T> for raw`.
    pub(crate) newtype: bool,
    /// The raw type it holds (`u16`): the entry's must be the same.
    pub(crate) raw: &'static str,
    /// It is the entry's value type itself (no generated type) while the
    /// entry keeps the standard's meaning; else a generated type converts
    /// to and from it.
    pub(crate) value: bool,
}

/// A bit field: `width` bits from `lsb`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct StdBit {
    pub(crate) lsb: u32,
    pub(crate) width: u32,
    pub(crate) name: &'static str,
    pub(crate) text: Option<&'static str>,
    pub(crate) unit: Option<&'static str>,
}

/// `raw & mask == value` names a state.
#[derive(Debug, Clone, Copy)]
pub(crate) struct StdPattern {
    pub(crate) name: &'static str,
    pub(crate) mask: u64,
    pub(crate) value: u64,
}

/// Named values (single values or inclusive ranges), the range that carries
/// a number, and the name of every other value.
#[derive(Debug, Clone, Copy)]
pub(crate) struct StdValues {
    pub(crate) numeric: Option<(i128, i128)>,
    pub(crate) named: &'static [(i128, i128, &'static str)],
    pub(crate) other: &'static str,
}

impl StdMeaning {
    /// One object's sub-entry `sub`, with nothing said yet.
    pub(crate) const fn at(index: u16, sub: u8) -> StdMeaning {
        StdMeaning {
            index,
            last: index,
            subs: (sub, sub),
            unit: None,
            scale: None,
            bits: &[],
            patterns: &[],
            values: None,
            runtime: None,
        }
    }

    /// The same sub-entry of objects `index..=last`.
    pub(crate) const fn objects(mut self, last: u16) -> StdMeaning {
        self.last = last;
        self
    }

    /// The same meaning for subs `first..=last`.
    pub(crate) const fn subs(mut self, first: u8, last: u8) -> StdMeaning {
        self.subs = (first, last);
        self
    }

    pub(crate) const fn unit(mut self, unit: &'static str) -> StdMeaning {
        self.unit = Some(unit);
        self
    }

    pub(crate) const fn scaled(mut self, unit: &'static str, scale: f64) -> StdMeaning {
        self.unit = Some(unit);
        self.scale = Some(scale);
        self
    }

    pub(crate) const fn bits(mut self, bits: &'static [StdBit]) -> StdMeaning {
        self.bits = bits;
        self
    }

    pub(crate) const fn patterns(mut self, patterns: &'static [StdPattern]) -> StdMeaning {
        self.patterns = patterns;
        self
    }

    pub(crate) const fn values(mut self, values: StdValues) -> StdMeaning {
        self.values = Some(values);
        self
    }

    pub(crate) const fn runtime(
        mut self,
        path: &'static str,
        raw: &'static str,
        newtype: bool,
    ) -> StdMeaning {
        self.runtime = Some(RuntimeType {
            path,
            newtype,
            raw,
            value: false,
        });
        self
    }

    /// The runtime type `path` (a tuple struct over `raw`) is the entry's
    /// value type while the entry keeps the standard's meaning.
    pub(crate) const fn runtime_value(
        mut self,
        path: &'static str,
        raw: &'static str,
    ) -> StdMeaning {
        self.runtime = Some(RuntimeType {
            path,
            newtype: true,
            raw,
            value: true,
        });
        self
    }

    pub(super) fn covers(&self, index: u16, sub: u8) -> bool {
        (self.index..=self.last).contains(&index) && (self.subs.0..=self.subs.1).contains(&sub)
    }
}

/// One bit.
pub(crate) const fn bit(lsb: u32, name: &'static str, text: Option<&'static str>) -> StdBit {
    StdBit {
        lsb,
        width: 1,
        name,
        text,
        unit: None,
    }
}

/// A field of `width` bits.
pub(crate) const fn field(
    lsb: u32,
    width: u32,
    name: &'static str,
    unit: Option<&'static str>,
) -> StdBit {
    StdBit {
        lsb,
        width,
        name,
        text: None,
        unit,
    }
}

pub(crate) const fn pattern(name: &'static str, mask: u64, value: u64) -> StdPattern {
    StdPattern { name, mask, value }
}
