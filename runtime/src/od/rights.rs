//! Access rights: as a value ([`AccessRight`]) and as types ([`access`]),
//! with the traits that let the compiler refuse a read of a write-only
//! object, a write of a read-only one, and a PDO mapping against an
//! object's direction.

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

pub(crate) mod sealed {
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
