//! The protocol cores, sans-IO: each is fed received frames and the current
//! time and hands out the frames to send, its events and its next deadline
//! through [`crate::Service`]. No core does I/O or reads a clock; the
//! drivers in `src/drivers/` and any caller of their own run them.
//!
//! The modules are re-exported at the crate root, where their documentation is.

/// `Default` for the cores whose default is their `new()` (a `const fn`,
/// which `Default::default` cannot be): the one place that says so.
macro_rules! default_is_new {
    ($core:ty) => {
        impl Default for $core {
            fn default() -> Self {
                <$core>::new()
            }
        }
    };
}

/// A public enum coded as one byte on the bus: the enum (`#[repr(u8)]`),
/// `from_byte` (`None` for other bytes), `to_byte` and `Display` (the
/// text given for each value), written once for the NMT commands and
/// states and the LSS states.
macro_rules! byte_enum {
    (
        $(#[$meta:meta])*
        pub enum $name:ident {
            $($(#[$vmeta:meta])* $variant:ident = $byte:literal => $text:literal,)+
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        #[repr(u8)]
        pub enum $name {
            $($(#[$vmeta])* $variant = $byte,)+
        }

        impl $name {
            /// The value coded `byte`; `None` for other bytes.
            pub const fn from_byte(byte: u8) -> Option<$name> {
                match byte {
                    $($byte => Some($name::$variant),)+
                    _ => None,
                }
            }

            /// The byte coding this value.
            pub const fn to_byte(self) -> u8 {
                self as u8
            }
        }

        impl core::fmt::Display for $name {
            fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                f.write_str(match self {
                    $($name::$variant => $text,)+
                })
            }
        }
    };
}

/// A public enum of consecutive indices from 0: the enum (`#[repr(u8)]`),
/// `ALL` (every value, in index order; its doc given) and `from_index`
/// (`None` past the last), written once for the parts of an LSS address
/// and the frames of identify remote slave.
macro_rules! indexed_enum {
    (
        $(#[$meta:meta])*
        pub enum $name:ident {
            $($(#[$vmeta:meta])* $variant:ident = $index:literal,)+
        }
        $(#[$all_meta:meta])*
        ALL;
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        #[repr(u8)]
        pub enum $name {
            $($(#[$vmeta])* $variant = $index,)+
        }

        impl $name {
            $(#[$all_meta])*
            pub const ALL: [$name; [$($index),+].len()] = [$($name::$variant),+];

            /// The value with index `index`; `None` for other values.
            pub const fn from_index(index: u8) -> Option<$name> {
                match index {
                    $($index => Some($name::$variant),)+
                    _ => None,
                }
            }

            /// The index.
            pub const fn index(self) -> u8 {
                self as u8
            }
        }
    };
}

#[cfg(feature = "alloc")]
pub mod boot;
pub mod cia402;
pub mod emcy;
pub(crate) mod error_control;
pub mod guarding;
pub mod heartbeat;
pub mod lss;
#[cfg(feature = "alloc")]
pub mod master;
pub mod nmt;
pub mod pdo;
pub mod sdo;
pub mod sync;
#[cfg(test)]
pub(crate) mod testing;
pub mod time_stamp;
