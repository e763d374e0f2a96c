//! Object-dictionary types shared by generated drivers and the protocol runtime.
//!
//! Generated code describes every object entry as a zero-sized type that
//! implements [`Entry`]: its index, subindex, CiA 301 data type, value type and
//! access right live in the type system. The functions here are generic over
//! those types, so that the compiler rejects a write to a read-only object
//! ([`encode_value`] needs [`Write`]), a read of a write-only object
//! ([`decode_value`] needs [`Read`]), a value of the wrong type, a
//! non-mappable object in a PDO mapping and an object mapped against its
//! direction ([`rpdo_mapping_entry`] needs [`PdoMappable`] and a writable
//! object, [`tpdo_mapping_entry`] a readable one). Everything here needs
//! only `core`.

use core::fmt;

mod array;
mod info;
mod pdo;
mod scaled;
pub mod standard;

pub use array::{Array, Element, Elements, array_subindex};
pub use info::{DefaultValue, Number, ObjectInfo};
pub use pdo::{Pdo, PdoDirection, PdoLengthError};
pub use scaled::{Scaled, ScaledRaw};

/// A CiA 301 basic data type.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DataType {
    Boolean,
    Integer8,
    Integer16,
    Integer24,
    Integer32,
    Integer40,
    Integer48,
    Integer56,
    Integer64,
    Unsigned8,
    Unsigned16,
    Unsigned24,
    Unsigned32,
    Unsigned40,
    Unsigned48,
    Unsigned56,
    Unsigned64,
    Real32,
    Real64,
    VisibleString,
    OctetString,
    UnicodeString,
    TimeOfDay,
    TimeDifference,
    Domain,
    /// A code outside the standard table (a DEFTYPE or vendor type).
    Other(u16),
}

impl DataType {
    /// The number of bytes a value takes on the bus, or `None` when the
    /// length is not fixed (strings, DOMAIN, unknown types).
    pub const fn size(self) -> Option<usize> {
        use DataType::*;
        match self {
            Boolean | Integer8 | Unsigned8 => Some(1),
            Integer16 | Unsigned16 => Some(2),
            Integer24 | Unsigned24 => Some(3),
            Integer32 | Unsigned32 | Real32 => Some(4),
            Integer40 | Unsigned40 => Some(5),
            Integer48 | Unsigned48 | TimeOfDay | TimeDifference => Some(6),
            Integer56 | Unsigned56 => Some(7),
            Integer64 | Unsigned64 | Real64 => Some(8),
            VisibleString | OctetString | UnicodeString | Domain | Other(_) => None,
        }
    }

    /// Whether raw values of this type are two's-complement signed integers.
    pub const fn is_signed(self) -> bool {
        use DataType::*;
        matches!(
            self,
            Integer8
                | Integer16
                | Integer24
                | Integer32
                | Integer40
                | Integer48
                | Integer56
                | Integer64
        )
    }
}

/// The access right of an entry, as a value.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum AccessRight {
    Ro,
    Wo,
    Rw,
    /// Read/write, mapped into a TPDO.
    Rwr,
    /// Read/write, mapped into an RPDO.
    Rww,
    Const,
}

/// Access rights as types; generated entries name one of these as
/// [`Entry::Access`].
pub mod access {
    /// Read only.
    pub enum Ro {}
    /// Write only.
    pub enum Wo {}
    /// Read and write.
    pub enum Rw {}
    /// Read and write; meant for TPDO mapping (process input).
    pub enum Rwr {}
    /// Read and write; meant for RPDO mapping (process output).
    pub enum Rww {}
    /// Read only, never changes.
    pub enum Const {}
}

mod sealed {
    use super::access::{Const, Ro, Rw, Rwr, Rww, Wo};

    pub trait Sealed {}
    impl Sealed for Ro {}
    impl Sealed for Wo {}
    impl Sealed for Rw {}
    impl Sealed for Rwr {}
    impl Sealed for Rww {}
    impl Sealed for Const {}

    /// The access rights [`super::RpdoAccess`] is implemented for (no other
    /// crate can add one).
    pub trait RpdoSealed<E> {}
    impl<E> RpdoSealed<E> for Wo {}
    impl<E> RpdoSealed<E> for Rw {}
    impl<E> RpdoSealed<E> for Rwr {}
    impl<E> RpdoSealed<E> for Rww {}

    /// The access rights [`super::TpdoAccess`] is implemented for.
    pub trait TpdoSealed<E> {}
    impl<E> TpdoSealed<E> for Ro {}
    impl<E> TpdoSealed<E> for Rw {}
    impl<E> TpdoSealed<E> for Rwr {}
    impl<E> TpdoSealed<E> for Rww {}
    impl<E> TpdoSealed<E> for Const {}
}

/// An access right as a type.
pub trait Access: sealed::Sealed {
    const RIGHT: AccessRight;
}

/// Access rights that allow reading over the bus.
#[diagnostic::on_unimplemented(
    message = "this object cannot be read: its access right is `{Self}`",
    label = "a write-only object"
)]
pub trait Read: Access {}

/// Access rights that allow writing over the bus.
#[diagnostic::on_unimplemented(
    message = "this object cannot be written: its access right is `{Self}`",
    label = "a read-only or constant object"
)]
pub trait Write: Access {}

impl Access for access::Ro {
    const RIGHT: AccessRight = AccessRight::Ro;
}
impl Access for access::Wo {
    const RIGHT: AccessRight = AccessRight::Wo;
}
impl Access for access::Rw {
    const RIGHT: AccessRight = AccessRight::Rw;
}
impl Access for access::Rwr {
    const RIGHT: AccessRight = AccessRight::Rwr;
}
impl Access for access::Rww {
    const RIGHT: AccessRight = AccessRight::Rww;
}
impl Access for access::Const {
    const RIGHT: AccessRight = AccessRight::Const;
}

impl Read for access::Ro {}
impl Read for access::Rw {}
impl Read for access::Rwr {}
impl Read for access::Rww {}
impl Read for access::Const {}

impl Write for access::Wo {}
impl Write for access::Rw {}
impl Write for access::Rwr {}
impl Write for access::Rww {}

/// Access rights of objects that may be mapped into an RPDO: the device
/// receives an RPDO and writes its values into the mapped objects, so they
/// must be writable (wo, rw, rwr, rww; not ro or const).
///
/// Implemented by the access types of [`access`]; `E` is the entry being
/// mapped, there only so that the compiler's error names it.
#[diagnostic::on_unimplemented(
    message = "`{E}` is read-only and cannot be mapped into an RPDO (the device receives RPDOs and writes their values)",
    label = "its access right `{Self}` does not allow writing",
    note = "a read-only object can be mapped into a TPDO (`tpdo_mapping_entry`) or read over SDO"
)]
pub trait RpdoAccess<E>: Write + sealed::RpdoSealed<E> {}

/// Access rights of objects that may be mapped into a TPDO: the device
/// reads the mapped objects and transmits their values, so they must be
/// readable (ro, const, rw, rwr, rww; not wo).
///
/// Implemented by the access types of [`access`]; `E` is the entry being
/// mapped, there only so that the compiler's error names it.
#[diagnostic::on_unimplemented(
    message = "`{E}` is write-only and cannot be mapped into a TPDO (the device transmits TPDOs and reads their values)",
    label = "its access right `{Self}` does not allow reading",
    note = "a write-only object can be mapped into an RPDO (`rpdo_mapping_entry`) or written over SDO"
)]
pub trait TpdoAccess<E>: Read + sealed::TpdoSealed<E> {}

impl<E> RpdoAccess<E> for access::Wo {}
impl<E> RpdoAccess<E> for access::Rw {}
impl<E> RpdoAccess<E> for access::Rwr {}
impl<E> RpdoAccess<E> for access::Rww {}

impl<E> TpdoAccess<E> for access::Ro {}
impl<E> TpdoAccess<E> for access::Rw {}
impl<E> TpdoAccess<E> for access::Rwr {}
impl<E> TpdoAccess<E> for access::Rww {}
impl<E> TpdoAccess<E> for access::Const {}

/// One object-dictionary entry (a VAR, or one sub-entry of an ARRAY or
/// RECORD), implemented by a generated zero-sized type. The elements of an
/// ARRAY are one generated type indexed by sub-index ([`Array`]).
pub trait Entry {
    const INDEX: u16;
    /// The sub-index (0 for a VAR, which generated code leaves to this default).
    const SUBINDEX: u8 = 0;
    /// The name in the source (EDS `ParameterName` or the YAML `name`).
    const NAME: &'static str;
    const DATA_TYPE: DataType;
    /// Whether the entry may be mapped into a PDO (generated code states only `true`).
    const PDO_MAPPABLE: bool = false;
    /// The access right as a type: [`access::Ro`], [`access::Rw`], ...
    type Access: Access;
    /// The typed value: a primitive, or a generated enum, bit-field struct or
    /// scaled newtype.
    type Value;
}

/// Entries that may be mapped into a PDO; generated only for those.
#[diagnostic::on_unimplemented(
    message = "`{Self}` cannot be mapped into a PDO",
    label = "this object is not PDO-mappable"
)]
pub trait PdoMappable: Entry {}

/// A value with a fixed-size raw form: primitives and generated value types.
///
/// `to_raw` gives the two's-complement bit pattern (bits above the data
/// type's width are ignored by encoders); `from_raw` receives the bit pattern
/// sign-extended to 64 bits for signed data types.
pub trait Scalar: Copy {
    fn to_raw(self) -> u64;
    fn from_raw(raw: u64) -> Self;
}

macro_rules! scalar_ints {
    ($($ty:ty),*) => {$(
        impl Scalar for $ty {
            #[inline(always)]
            fn to_raw(self) -> u64 { self as u64 }
            #[inline(always)]
            fn from_raw(raw: u64) -> Self { raw as $ty }
        }
    )*};
}

scalar_ints!(u8, u16, u32, u64, i8, i16, i32, i64);

impl Scalar for bool {
    #[inline]
    fn to_raw(self) -> u64 {
        self as u64
    }
    #[inline]
    fn from_raw(raw: u64) -> Self {
        raw & 1 != 0
    }
}

impl Scalar for f32 {
    #[inline]
    fn to_raw(self) -> u64 {
        u64::from(self.to_bits())
    }
    #[inline]
    fn from_raw(raw: u64) -> Self {
        f32::from_bits(raw as u32)
    }
}

impl Scalar for f64 {
    #[inline]
    fn to_raw(self) -> u64 {
        self.to_bits()
    }
    #[inline]
    fn from_raw(raw: u64) -> Self {
        f64::from_bits(raw)
    }
}

/// Value types of entries without a fixed length; read and written as bytes.
pub mod bytes {
    /// VISIBLE_STRING: ISO 646 text.
    pub enum VisibleString {}
    /// OCTET_STRING: raw bytes.
    pub enum OctetString {}
    /// UNICODE_STRING: UTF-16 code units.
    pub enum UnicodeString {}
    /// DOMAIN: a block of data of any length.
    pub enum Domain {}
    /// A data type this crate does not know (DEFTYPE, vendor code).
    pub enum Opaque {}
}

/// Value types read and written as a byte sequence of any length (the
/// markers of [`bytes`]); SDO drivers offer byte-buffer access for them.
pub trait ByteValue: sealed::Sealed {
    /// The CiA 301 data type the marker stands for (DOMAIN for [`bytes::Opaque`]).
    const DATA_TYPE: DataType;
}

impl sealed::Sealed for bytes::VisibleString {}
impl sealed::Sealed for bytes::OctetString {}
impl sealed::Sealed for bytes::UnicodeString {}
impl sealed::Sealed for bytes::Domain {}
impl sealed::Sealed for bytes::Opaque {}
impl ByteValue for bytes::VisibleString {
    const DATA_TYPE: DataType = DataType::VisibleString;
}
impl ByteValue for bytes::OctetString {
    const DATA_TYPE: DataType = DataType::OctetString;
}
impl ByteValue for bytes::UnicodeString {
    const DATA_TYPE: DataType = DataType::UnicodeString;
}
impl ByteValue for bytes::Domain {
    const DATA_TYPE: DataType = DataType::Domain;
}
impl ByteValue for bytes::Opaque {
    const DATA_TYPE: DataType = DataType::Domain;
}

/// A device's error table, as generated from its EDS/YAML `errors:` section
/// (an enum with one variant per listed code and a fallback for the rest).
/// The EMCY consumer uses it to name the codes a device reports.
pub trait ErrorTable: Copy + fmt::Debug + fmt::Display {
    /// Looks a code up: `None` when it does not fit the table's code type,
    /// the fallback variant when the table does not list it.
    fn lookup(code: u64) -> Option<Self>;
    /// The numeric code.
    fn code(self) -> u64;
    /// Whether the code is listed in the table.
    fn is_known(self) -> bool;
    /// The short name from the table.
    fn name(self) -> &'static str;
    /// The description from the table.
    fn text(self) -> &'static str;
    /// The device's reaction, when the table states one.
    fn reaction(self) -> Option<&'static str>;
    /// What to do about it, when the table states it.
    fn remedy(self) -> Option<&'static str>;
}

/// Why a value could not be encoded or decoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum ValueError {
    /// The buffer holds `actual` bytes; the data type needs `expected`.
    Length { expected: usize, actual: usize },
    /// The data type has no fixed length.
    NotFixedSize(DataType),
}

impl fmt::Display for ValueError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ValueError::Length { expected, actual } => {
                write!(f, "expected {expected} bytes, got {actual}")
            }
            ValueError::NotFixedSize(t) => write!(f, "{t:?} has no fixed length"),
        }
    }
}

/// Encodes the value of a writable entry into its little-endian bus form
/// (the data of an SDO download); returns the number of bytes written.
pub fn encode_value<E>(value: E::Value, out: &mut [u8]) -> Result<usize, ValueError>
where
    E: Entry,
    E::Access: Write,
    E::Value: Scalar,
{
    let size = E::DATA_TYPE
        .size()
        .ok_or(ValueError::NotFixedSize(E::DATA_TYPE))?;
    let actual = out.len();
    let Some(dest) = out.get_mut(..size) else {
        return Err(ValueError::Length {
            expected: size,
            actual,
        });
    };
    let raw = value.to_raw().to_le_bytes();
    for (d, s) in dest.iter_mut().zip(raw.iter()) {
        *d = *s;
    }
    Ok(size)
}

/// Decodes the value of a readable entry from its little-endian bus form (the
/// data of an SDO upload); the slice must have exactly the type's length.
pub fn decode_value<E>(bytes: &[u8]) -> Result<E::Value, ValueError>
where
    E: Entry,
    E::Access: Read,
    E::Value: Scalar,
{
    let size = E::DATA_TYPE
        .size()
        .ok_or(ValueError::NotFixedSize(E::DATA_TYPE))?;
    if bytes.len() != size {
        return Err(ValueError::Length {
            expected: size,
            actual: bytes.len(),
        });
    }
    let mut raw = 0u64;
    for (i, b) in bytes.iter().enumerate() {
        raw |= u64::from(*b) << (8 * i);
    }
    if E::DATA_TYPE.is_signed() && size < 8 {
        let shift = 64 - 8 * size as u32;
        raw = (((raw << shift) as i64) >> shift) as u64;
    }
    Ok(E::Value::from_raw(raw))
}

/// The mapping value of entry `E` in an RPDO (`index << 16 | subindex << 8
/// | bits`), as written into an RPDO mapping parameter (0x1600 to 0x17FF).
///
/// Compiles only for a PDO-mappable, writable entry: the device writes the
/// values of an RPDO it receives into the mapped objects, so a read-only or
/// constant object has no place in one. Usable in constants:
///
/// ```
/// use eds2rust_runtime::od::{DataType, Entry, PdoMappable, access};
/// use eds2rust_runtime::od::{rpdo_mapping_entry, tpdo_mapping_entry};
///
/// // What generated code declares for CiA 402's controlword (rw) and
/// // statusword (ro).
/// struct Controlword;
/// impl Entry for Controlword {
///     const INDEX: u16 = 0x6040;
///     const SUBINDEX: u8 = 0;
///     const NAME: &'static str = "Controlword";
///     const DATA_TYPE: DataType = DataType::Unsigned16;
///     const PDO_MAPPABLE: bool = true;
///     type Access = access::Rw;
///     type Value = u16;
/// }
/// impl PdoMappable for Controlword {}
/// struct Statusword;
/// impl Entry for Statusword {
///     const INDEX: u16 = 0x6041;
///     const SUBINDEX: u8 = 0;
///     const NAME: &'static str = "Statusword";
///     const DATA_TYPE: DataType = DataType::Unsigned16;
///     const PDO_MAPPABLE: bool = true;
///     type Access = access::Ro;
///     type Value = u16;
/// }
/// impl PdoMappable for Statusword {}
///
/// const RPDO1: [u32; 1] = [rpdo_mapping_entry::<Controlword>()];
/// const TPDO1: [u32; 1] = [tpdo_mapping_entry::<Statusword>()];
/// assert_eq!((RPDO1, TPDO1), ([0x6040_0010], [0x6041_0010]));
/// ```
///
/// The statusword is read-only, so it does not go into an RPDO:
///
/// ```compile_fail,E0277
/// # use eds2rust_runtime::od::{DataType, Entry, PdoMappable, access, rpdo_mapping_entry};
/// # struct Statusword;
/// # impl Entry for Statusword {
/// #     const INDEX: u16 = 0x6041;
/// #     const SUBINDEX: u8 = 0;
/// #     const NAME: &'static str = "Statusword";
/// #     const DATA_TYPE: DataType = DataType::Unsigned16;
/// #     const PDO_MAPPABLE: bool = true;
/// #     type Access = access::Ro;
/// #     type Value = u16;
/// # }
/// # impl PdoMappable for Statusword {}
/// const RPDO1: [u32; 1] = [rpdo_mapping_entry::<Statusword>()];
/// ```
pub const fn rpdo_mapping_entry<E>() -> u32
where
    E: PdoMappable,
    E::Access: RpdoAccess<E>,
{
    mapping_value::<E>()
}

/// The mapping value of entry `E` in a TPDO (`index << 16 | subindex << 8 |
/// bits`), as written into a TPDO mapping parameter (0x1A00 to 0x1BFF).
///
/// Compiles only for a PDO-mappable, readable entry: the device reads the
/// mapped objects to fill a TPDO, so a write-only object has no place in
/// one.
pub const fn tpdo_mapping_entry<E>() -> u32
where
    E: PdoMappable,
    E::Access: TpdoAccess<E>,
{
    mapping_value::<E>()
}

/// The PDO mapping value of an entry (`index << 16 | subindex << 8 | bits`),
/// without a direction.
///
/// Deprecated: it lets a read-only object into an RPDO mapping and a
/// write-only one into a TPDO mapping. Every mapping has a direction, so
/// use [`rpdo_mapping_entry`] or [`tpdo_mapping_entry`], which check it
/// (a read-write object passes both).
#[deprecated(
    since = "0.1.0",
    note = "use `rpdo_mapping_entry` or `tpdo_mapping_entry`, which check that the object may be mapped in that direction"
)]
pub const fn mapping_entry<E: PdoMappable>() -> u32 {
    mapping_value::<E>()
}

/// `index << 16 | subindex << 8 | bits` of `E` (bits 0 without a fixed size).
const fn mapping_value<E: Entry>() -> u32 {
    mapping_bits(E::INDEX, E::SUBINDEX, E::DATA_TYPE)
}

/// `index << 16 | subindex << 8 | bits` (bits 0 without a fixed size).
const fn mapping_bits(index: u16, subindex: u8, data_type: DataType) -> u32 {
    let bits = match data_type.size() {
        Some(bytes) => bytes as u32 * 8,
        None => 0,
    };
    (index as u32) << 16 | (subindex as u32) << 8 | bits
}

/// A CANopen node id, 1 to 127.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct NodeId(u8);

impl NodeId {
    /// `None` unless `id` is 1 to 127.
    pub const fn new(id: u8) -> Option<NodeId> {
        if id >= 1 && id <= 127 {
            Some(NodeId(id))
        } else {
            None
        }
    }

    pub const fn get(self) -> u8 {
        self.0
    }
}

impl fmt::Display for NodeId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0)
    }
}
