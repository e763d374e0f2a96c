//! Scaled values: a raw number with a unit, a scale and an offset. The
//! conversions to and from the physical value live here; a generated scaled
//! type only declares its constants and implements [`Scaled`].

/// A raw number type of a scaled value (the integer and float primitives).
pub trait ScaledRaw: Copy + sealed::Sealed {
    /// The lowest value of the type.
    const MIN: Self;
    /// The highest value of the type.
    const MAX: Self;
    /// The value as `f64`.
    fn to_f64(self) -> f64;
    /// The raw value nearest to `steps` (halves away from zero), or `None`
    /// when that is outside `min..=max` or `steps` is NaN. A float takes
    /// `steps` as it is.
    fn from_steps(steps: f64, min: Self, max: Self) -> Option<Self>;
}

mod sealed {
    pub trait Sealed {}
}

/// `ScaledRaw` for the primitive types `$ty`, with `from_steps` as given
/// (the integers round and check their range, the floats take the steps).
macro_rules! scaled_raw {
    ($($ty:ty),* => |$steps:ident, $min:ident, $max:ident| $from_steps:expr) => {$(
        impl sealed::Sealed for $ty {}
        impl ScaledRaw for $ty {
            const MIN: Self = <$ty>::MIN;
            const MAX: Self = <$ty>::MAX;
            #[inline]
            fn to_f64(self) -> f64 {
                self as f64
            }
            #[inline]
            fn from_steps($steps: f64, $min: Self, $max: Self) -> Option<Self> {
                $from_steps
            }
        }
    )*};
}

scaled_raw!(u8, u16, u32, u64, i8, i16, i32, i64 => |steps, min, max| {
    let rounded = round_steps(steps, min as f64, max as f64)?;
    if rounded < min as i128 || rounded > max as i128 {
        return None;
    }
    Some(rounded as Self)
});

scaled_raw!(f32, f64 => |steps, _min, _max| Some(steps as Self));

/// `steps` rounded half away from zero, or `None` when it is NaN or more
/// than one step outside `min..=max`.
#[inline]
fn round_steps(steps: f64, min: f64, max: f64) -> Option<i128> {
    if !(steps > min - 1.0 && steps < max + 1.0) {
        return None;
    }
    let truncated = steps as i128;
    let fraction = steps - truncated as f64;
    Some(if fraction >= 0.5 {
        truncated + 1
    } else if fraction <= -0.5 {
        truncated - 1
    } else {
        truncated
    })
}

/// The integer `1 / scale` when `scale` is its reciprocal (0.1 → 10):
/// dividing by it gives the correctly rounded decimal (26 → 2.6, not
/// 2.6000000000000005).
#[inline]
fn divisor(scale: f64) -> Option<f64> {
    let reciprocal = 1.0 / scale;
    if scale.is_nan() || scale.abs() >= 1.0 || reciprocal.abs() >= 9.0e18 {
        return None;
    }
    let half = if reciprocal < 0.0 { -0.5 } else { 0.5 };
    let rounded = (reciprocal + half) as i64 as f64;
    let exact = rounded != 0.0 && (reciprocal - rounded).abs() < 1e-9 * rounded.abs();
    exact.then_some(rounded)
}

/// A number with a unit: physical value = raw × [`SCALE`](Scaled::SCALE) +
/// [`OFFSET`](Scaled::OFFSET). Generated scaled types implement it with
/// their constants; the conversions are provided.
///
/// ```
/// use eds2rust_runtime::od::Scaled;
///
/// #[derive(Debug, Clone, Copy, PartialEq)]
/// struct Position(u16);
/// impl Scaled for Position {
///     type Raw = u16;
///     const UNIT: &'static str = "mm";
///     const SCALE: f64 = 0.1;
///     const MAX_RAW: u16 = 0xFAFF;
///     fn from_raw(raw: u16) -> Self {
///         Self(raw)
///     }
///     fn to_raw(self) -> u16 {
///         self.0
///     }
/// }
///
/// assert_eq!(Position(26).value(), 2.6);
/// assert_eq!(Position::from_value(12.34), Some(Position(123)));
/// assert_eq!(Position::from_value(6425.6), None);
/// assert_eq!(Position::from_value(f64::NAN), None);
/// ```
pub trait Scaled: Copy {
    /// The raw type on the bus.
    type Raw: ScaledRaw;
    /// The unit of [`value`](Scaled::value) (empty when none is given).
    const UNIT: &'static str = "";
    /// Physical value of one raw step.
    const SCALE: f64 = 1.0;
    /// Physical value of raw 0.
    const OFFSET: f64 = 0.0;
    /// The lowest raw value that is a number.
    const MIN_RAW: Self::Raw = <Self::Raw as ScaledRaw>::MIN;
    /// The highest raw value that is a number.
    const MAX_RAW: Self::Raw = <Self::Raw as ScaledRaw>::MAX;

    /// The value with this raw form.
    fn from_raw(raw: Self::Raw) -> Self;
    /// The raw form on the bus.
    fn to_raw(self) -> Self::Raw;

    /// The physical value: raw × `SCALE` + `OFFSET`.
    #[inline]
    fn value(self) -> f64 {
        let raw = self.to_raw().to_f64();
        match divisor(Self::SCALE) {
            Some(k) => raw / k + Self::OFFSET,
            None => raw * Self::SCALE + Self::OFFSET,
        }
    }

    /// The raw value nearest to `value`, or `None` when that is outside
    /// `MIN_RAW..=MAX_RAW` or `value` is NaN (a float raw type takes the
    /// quotient as it is).
    #[inline]
    fn from_value(value: f64) -> Option<Self> {
        let steps = match divisor(Self::SCALE) {
            Some(k) => (value - Self::OFFSET) * k,
            None => (value - Self::OFFSET) / Self::SCALE,
        };
        ScaledRaw::from_steps(steps, Self::MIN_RAW, Self::MAX_RAW).map(Self::from_raw)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Clone, Copy, PartialEq)]
    struct Temperature(i16);
    impl Scaled for Temperature {
        type Raw = i16;
        const UNIT: &'static str = "°C";
        const SCALE: f64 = 0.5;
        const OFFSET: f64 = -40.0;
        const MIN_RAW: i16 = -100;
        fn from_raw(raw: i16) -> Self {
            Self(raw)
        }
        fn to_raw(self) -> i16 {
            self.0
        }
    }

    #[derive(Debug, Clone, Copy, PartialEq)]
    struct Gain(f32);
    impl Scaled for Gain {
        type Raw = f32;
        const SCALE: f64 = 3.0;
        fn from_raw(raw: f32) -> Self {
            Self(raw)
        }
        fn to_raw(self) -> f32 {
            self.0
        }
    }

    #[test]
    fn integer_raws_round_to_the_nearest_step_in_range() {
        assert_eq!(Temperature(10).value(), -35.0);
        assert_eq!(Temperature::from_value(-35.0), Some(Temperature(10)));
        assert_eq!(Temperature::from_value(-35.2), Some(Temperature(10)));
        assert_eq!(Temperature::from_value(-35.25), Some(Temperature(10)));
        assert_eq!(Temperature::from_value(-35.3), Some(Temperature(9)));
        assert_eq!(Temperature::from_value(-90.0), Some(Temperature(-100)));
        assert_eq!(Temperature::from_value(-90.5), None);
        assert_eq!(Temperature::from_value(16_400.0), None);
        assert_eq!(Temperature::from_value(f64::NAN), None);
        for raw in -100..=i16::MAX {
            let t = Temperature(raw);
            assert_eq!(Temperature::from_value(t.value()), Some(t));
        }
    }

    #[test]
    fn a_reciprocal_scale_divides() {
        assert_eq!(divisor(0.1), Some(10.0));
        assert_eq!(divisor(-0.25), Some(-4.0));
        assert_eq!(divisor(0.3), None);
        assert_eq!(divisor(2.0), None);
        assert_eq!(divisor(1e-300), None);
    }

    #[test]
    fn float_raws_take_the_quotient() {
        assert_eq!(Gain(2.0).value(), 6.0);
        assert_eq!(Gain::from_value(7.5), Some(Gain(2.5)));
    }
}
