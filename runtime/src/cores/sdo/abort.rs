//! SDO abort codes (CiA 301, table "SDO abort codes") as a typed value.

use core::fmt;

macro_rules! abort_codes {
    ($($(#[$doc:meta])* $name:ident = $code:literal, $text:literal;)*) => {
        /// Why an SDO transfer was aborted. Every code CiA 301 defines has a
        /// variant; any other value is kept in [`AbortCode::Other`], so that
        /// every 32-bit value round-trips.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum AbortCode {
            $($(#[$doc])* $name,)*
            /// A code CiA 301 does not define (device- or profile-specific).
            Other(u32),
        }

        impl AbortCode {
            /// Every code CiA 301 defines, in numeric order.
            pub const ALL: &'static [AbortCode] = &[$(AbortCode::$name,)*];

            pub const fn from_code(code: u32) -> AbortCode {
                match code {
                    $($code => AbortCode::$name,)*
                    other => AbortCode::Other(other),
                }
            }

            pub const fn code(self) -> u32 {
                match self {
                    $(AbortCode::$name => $code,)*
                    AbortCode::Other(code) => code,
                }
            }

            /// The meaning CiA 301 gives the code; `None` for [`AbortCode::Other`].
            pub const fn description(self) -> Option<&'static str> {
                match self {
                    $(AbortCode::$name => Some($text),)*
                    AbortCode::Other(_) => None,
                }
            }
        }
    };
}

abort_codes! {
    ToggleBitNotAlternated = 0x0503_0000, "toggle bit not alternated";
    Timeout = 0x0504_0000, "SDO protocol timed out";
    InvalidCommand = 0x0504_0001, "client/server command specifier not valid or unknown";
    InvalidBlockSize = 0x0504_0002, "invalid block size (block mode only)";
    InvalidSequenceNumber = 0x0504_0003, "invalid sequence number (block mode only)";
    CrcError = 0x0504_0004, "CRC error (block mode only)";
    OutOfMemory = 0x0504_0005, "out of memory";
    UnsupportedAccess = 0x0601_0000, "unsupported access to an object";
    ReadWriteOnly = 0x0601_0001, "attempt to read a write only object";
    WriteReadOnly = 0x0601_0002, "attempt to write a read only object";
    ObjectDoesNotExist = 0x0602_0000, "object does not exist in the object dictionary";
    CannotMap = 0x0604_0041, "object cannot be mapped to the PDO";
    PdoLengthExceeded = 0x0604_0042, "the number and length of the objects to be mapped would exceed PDO length";
    ParameterIncompatible = 0x0604_0043, "general parameter incompatibility reason";
    InternalIncompatible = 0x0604_0047, "general internal incompatibility in the device";
    HardwareError = 0x0606_0000, "access failed due to a hardware error";
    LengthMismatch = 0x0607_0010, "data type does not match, length of service parameter does not match";
    LengthTooHigh = 0x0607_0012, "data type does not match, length of service parameter too high";
    LengthTooLow = 0x0607_0013, "data type does not match, length of service parameter too low";
    SubindexDoesNotExist = 0x0609_0011, "sub-index does not exist";
    InvalidValue = 0x0609_0030, "invalid value for parameter (download only)";
    ValueTooHigh = 0x0609_0031, "value of parameter written too high (download only)";
    ValueTooLow = 0x0609_0032, "value of parameter written too low (download only)";
    MaxBelowMin = 0x0609_0036, "maximum value is less than minimum value";
    ResourceNotAvailable = 0x060A_0023, "resource not available: SDO connection";
    GeneralError = 0x0800_0000, "general error";
    CannotTransfer = 0x0800_0020, "data cannot be transferred or stored to the application";
    CannotTransferLocalControl = 0x0800_0021, "data cannot be transferred or stored to the application because of local control";
    CannotTransferDeviceState = 0x0800_0022, "data cannot be transferred or stored to the application because of the present device state";
    NoObjectDictionary = 0x0800_0023, "object dictionary dynamic generation fails or no object dictionary is present";
    NoDataAvailable = 0x0800_0024, "no data available";
}

impl fmt::Display for AbortCode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.description() {
            Some(text) => write!(f, "{:#010X} ({text})", self.code()),
            None => write!(f, "{:#010X} (not defined by CiA 301)", self.code()),
        }
    }
}

impl From<u32> for AbortCode {
    fn from(code: u32) -> AbortCode {
        AbortCode::from_code(code)
    }
}

impl From<AbortCode> for u32 {
    fn from(code: AbortCode) -> u32 {
        code.code()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_defined_code_round_trips_and_is_sorted() {
        assert_eq!(AbortCode::ALL.len(), 31);
        for pair in AbortCode::ALL.windows(2) {
            assert!(pair[0].code() < pair[1].code());
        }
        for &code in AbortCode::ALL {
            assert_eq!(AbortCode::from_code(code.code()), code);
            assert!(code.description().is_some());
        }
        assert_eq!(
            AbortCode::from_code(0x1234_5678),
            AbortCode::Other(0x1234_5678)
        );
        assert_eq!(
            AbortCode::from_code(0x0602_0000),
            AbortCode::ObjectDoesNotExist
        );
    }
}
