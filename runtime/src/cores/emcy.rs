//! Emergency messages (EMCY, CiA 301): the message layout, the error
//! register, the standard error-code classes and a consumer that collects the
//! EMCY frames of the nodes on the bus (default COB-IDs 0x081..=0x0FF).
//!
//! Layout (8 data bytes): error code (little endian) in bytes 0-1, the error
//! register (object 0x1001) in byte 2, manufacturer-specific data in 3-7.

use core::fmt;

use crate::frame::cob;
use crate::od::{ErrorTable, NodeId};
use crate::queue::Ring;
use crate::{Frame, Instant, Service};

/// One emergency message.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Emcy {
    /// Error code; 0x0000 means "error reset or no error".
    pub code: u16,
    /// The error register (object 0x1001) at the time of the message.
    pub register: u8,
    /// Manufacturer-specific error information.
    pub manufacturer: [u8; 5],
}

/// An EMCY frame without exactly 8 data bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct EmcyParseError {
    /// The number of data bytes found.
    pub len: usize,
}

impl fmt::Display for EmcyParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "EMCY message has {} data bytes; CiA 301 requires exactly 8",
            self.len
        )
    }
}

impl core::error::Error for EmcyParseError {}

impl Emcy {
    /// Decodes the data of an EMCY frame; it must be exactly 8 bytes.
    pub fn parse(data: &[u8]) -> Result<Emcy, EmcyParseError> {
        let &[c0, c1, register, m0, m1, m2, m3, m4] = data else {
            return Err(EmcyParseError { len: data.len() });
        };
        Ok(Emcy {
            code: u16::from_le_bytes([c0, c1]),
            register,
            manufacturer: [m0, m1, m2, m3, m4],
        })
    }

    /// The 8 data bytes of the message.
    pub const fn to_bytes(&self) -> [u8; 8] {
        let [c0, c1] = self.code.to_le_bytes();
        let [m0, m1, m2, m3, m4] = self.manufacturer;
        [c0, c1, self.register, m0, m1, m2, m3, m4]
    }

    /// Whether this is an "error reset or no error" message (code 0x0000).
    pub const fn is_reset(&self) -> bool {
        self.code == 0
    }

    /// The error register with named bits.
    pub const fn error_register(&self) -> ErrorRegister {
        ErrorRegister(self.register)
    }

    /// The code looked up in a device's generated error table: the table's
    /// fallback variant for codes it does not list, `None` when the code does
    /// not fit the table's code type (see [`ErrorTable::lookup`]).
    pub fn describe<T: ErrorTable>(&self) -> Option<T> {
        T::lookup(u64::from(self.code))
    }

    /// The CiA 301 class of the code (see [`error_class`]).
    pub const fn class(&self) -> &'static str {
        error_class(self.code)
    }
}

impl fmt::Display for Emcy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "EMCY {:#06x} ({}), error register {:#04x}",
            self.code,
            self.class(),
            self.register
        )
    }
}

/// The error register (object 0x1001; byte 2 of an EMCY message).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct ErrorRegister(pub u8);

impl ErrorRegister {
    /// The raw byte.
    pub const fn bits(self) -> u8 {
        self.0
    }
    /// Bit 0: generic error (set whenever any error is present).
    pub const fn generic(self) -> bool {
        self.0 & 0x01 != 0
    }
    /// Bit 1: current.
    pub const fn current(self) -> bool {
        self.0 & 0x02 != 0
    }
    /// Bit 2: voltage.
    pub const fn voltage(self) -> bool {
        self.0 & 0x04 != 0
    }
    /// Bit 3: temperature.
    pub const fn temperature(self) -> bool {
        self.0 & 0x08 != 0
    }
    /// Bit 4: communication error (overrun, error state).
    pub const fn communication(self) -> bool {
        self.0 & 0x10 != 0
    }
    /// Bit 5: device-profile specific.
    pub const fn device_profile(self) -> bool {
        self.0 & 0x20 != 0
    }
    /// Bit 7: manufacturer specific.
    pub const fn manufacturer(self) -> bool {
        self.0 & 0x80 != 0
    }
}

/// The EMCY frame of `node` (default COB-ID 0x080 + node) carrying `emcy`.
pub const fn emcy_frame(node: NodeId, emcy: &Emcy) -> Frame {
    Frame::standard(cob::emcy(node), emcy.to_bytes(), 8)
}

/// Names the CiA 301 class of an emergency error code, the most specific
/// match first: an exact code (0x8110..0x8250), then the high byte (0x21xx
/// "current, device input side"), then the high nibble for codes within a
/// class but outside the listed sub-classes (0x24xx "current"). Codes in no
/// class give "unknown error class".
pub const fn error_class(code: u16) -> &'static str {
    match code {
        0x8110 => return "CAN overrun (objects lost)",
        0x8120 => return "CAN in error passive mode",
        0x8130 => return "life guard or heartbeat error",
        0x8140 => return "recovered from bus off",
        0x8150 => return "CAN-ID collision",
        0x8210 => return "PDO not processed due to length error",
        0x8220 => return "PDO length exceeded",
        0x8230 => return "DAM MPDO not processed, destination object not available",
        0x8240 => return "unexpected SYNC data length",
        0x8250 => return "RPDO timeout",
        _ => {}
    }
    match code >> 8 {
        0x00 => return "error reset or no error",
        0x10 => return "generic error",
        0x20 => return "current",
        0x21 => return "current, device input side",
        0x22 => return "current inside the device",
        0x23 => return "current, device output side",
        0x30 => return "voltage",
        0x31 => return "mains voltage",
        0x32 => return "voltage inside the device",
        0x33 => return "output voltage",
        0x40 => return "temperature",
        0x41 => return "ambient temperature",
        0x42 => return "device temperature",
        0x50 => return "device hardware",
        0x60 => return "device software",
        0x61 => return "internal software",
        0x62 => return "user software",
        0x63 => return "data set",
        0x70 => return "additional modules",
        0x80 => return "monitoring",
        0x81 => return "communication",
        0x82 => return "protocol error",
        0x90 => return "external error",
        0xF0 => return "additional functions",
        0xFF => return "device specific",
        _ => {}
    }
    match code >> 12 {
        0x1 => "generic error",
        0x2 => "current",
        0x3 => "voltage",
        0x4 => "temperature",
        0x5 => "device hardware",
        0x6 => "device software",
        0x7 => "additional modules",
        0x8 => "monitoring",
        0x9 => "external error",
        _ => "unknown error class",
    }
}

/// What an [`EmcyConsumer`] received.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum EmcyEvent {
    /// A well-formed emergency message from `node`.
    Emergency {
        /// The sender (COB-ID − 0x080).
        node: NodeId,
        /// The decoded message.
        emcy: Emcy,
    },
    /// A frame on `node`'s EMCY COB-ID without exactly 8 data bytes.
    Malformed {
        /// The sender (COB-ID − 0x080).
        node: NodeId,
        /// The number of data bytes received.
        len: usize,
    },
}

/// Number of events an [`EmcyConsumer`] keeps; when full, the oldest is
/// dropped and counted.
pub const CONSUMER_EVENTS: usize = 32;

/// EMCY consumer: reports the emergency messages of the watched nodes
/// (all nodes by default) on their default COB-IDs 0x080 + node. Remote
/// frames are ignored; data frames with a wrong length are reported as
/// [`EmcyEvent::Malformed`].
#[derive(Debug, Clone)]
pub struct EmcyConsumer {
    /// Bit n set: node n is watched.
    watched: u128,
    events: Ring<EmcyEvent, CONSUMER_EVENTS>,
}

default_is_new!(EmcyConsumer);

impl EmcyConsumer {
    /// A consumer watching all nodes 1 to 127.
    pub const fn new() -> EmcyConsumer {
        EmcyConsumer {
            watched: !1,
            events: Ring::new(),
        }
    }

    /// A consumer watching only `nodes`.
    pub fn only(nodes: &[NodeId]) -> EmcyConsumer {
        let mut consumer = EmcyConsumer {
            watched: 0,
            events: Ring::new(),
        };
        for node in nodes {
            consumer.watch(*node);
        }
        consumer
    }

    /// Starts watching `node`.
    pub fn watch(&mut self, node: NodeId) {
        self.watched |= 1u128 << node.get();
    }

    /// Stops watching `node`.
    pub fn unwatch(&mut self, node: NodeId) {
        self.watched &= !(1u128 << node.get());
    }

    /// Whether `node` is watched.
    pub const fn is_watched(&self, node: NodeId) -> bool {
        self.watched & (1u128 << node.get()) != 0
    }

    /// Events dropped because the event queue was full.
    pub fn dropped_events(&self) -> u32 {
        self.events.dropped()
    }
}

impl Service for EmcyConsumer {
    type Event = EmcyEvent;

    fn handle_frame(&mut self, _now: Instant, frame: &Frame) {
        if frame.is_remote() {
            return;
        }
        let Some(node) = frame
            .standard_id()
            .and_then(|id| id.checked_sub(0x080))
            .and_then(|n| u8::try_from(n).ok())
            .and_then(NodeId::new)
        else {
            return;
        };
        if !self.is_watched(node) {
            return;
        }
        self.events.push(match Emcy::parse(frame.data()) {
            Ok(emcy) => EmcyEvent::Emergency { node, emcy },
            Err(EmcyParseError { len }) => EmcyEvent::Malformed { node, len },
        });
    }

    fn poll_event(&mut self) -> Option<EmcyEvent> {
        self.events.pop()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CanId;
    use crate::cores::testing::{data, events, node};

    #[test]
    fn parse_cia301_layout() {
        // 081#1000010000000000: generic error, register bit 0.
        let e = Emcy::parse(&[0x00, 0x10, 0x01, 0, 0, 0, 0, 0]).unwrap();
        assert_eq!(e.code, 0x1000);
        assert_eq!(e.register, 0x01);
        assert!(e.error_register().generic());
        assert!(!e.is_reset());
        let e = Emcy::parse(&[0x30, 0x81, 0x11, 1, 2, 3, 4, 5]).unwrap();
        assert_eq!(e.code, 0x8130);
        assert_eq!(e.manufacturer, [1, 2, 3, 4, 5]);
        assert!(e.error_register().communication());
        assert_eq!(e.class(), "life guard or heartbeat error");
        assert_eq!(e.to_bytes(), [0x30, 0x81, 0x11, 1, 2, 3, 4, 5]);
        assert!(Emcy::parse(&[0; 8]).unwrap().is_reset());
    }

    #[test]
    fn wrong_length_is_an_error() {
        assert_eq!(Emcy::parse(&[]), Err(EmcyParseError { len: 0 }));
        assert_eq!(Emcy::parse(&[0; 7]), Err(EmcyParseError { len: 7 }));
        assert_eq!(Emcy::parse(&[0; 9]), Err(EmcyParseError { len: 9 }));
    }

    #[test]
    fn error_register_bits() {
        let r = ErrorRegister(0b1011_1110);
        assert!(!r.generic());
        assert!(r.current() && r.voltage() && r.temperature());
        assert!(r.communication() && r.device_profile() && r.manufacturer());
        assert_eq!(r.bits(), 0xBE);
        assert!(!ErrorRegister(0x40).manufacturer());
    }

    #[test]
    fn classes_most_specific_first() {
        assert_eq!(error_class(0x0000), "error reset or no error");
        assert_eq!(error_class(0x1000), "generic error");
        assert_eq!(error_class(0x2130), "current, device input side");
        assert_eq!(error_class(0x2310), "current, device output side");
        assert_eq!(error_class(0x2400), "current");
        assert_eq!(error_class(0x3210), "voltage inside the device");
        assert_eq!(error_class(0x4210), "device temperature");
        assert_eq!(error_class(0x5113), "device hardware");
        assert_eq!(error_class(0x6320), "data set");
        assert_eq!(error_class(0x8110), "CAN overrun (objects lost)");
        assert_eq!(error_class(0x8111), "communication");
        assert_eq!(error_class(0x8140), "recovered from bus off");
        assert_eq!(error_class(0x8250), "RPDO timeout");
        assert_eq!(error_class(0x8260), "protocol error");
        assert_eq!(error_class(0x8400), "monitoring");
        assert_eq!(error_class(0x9000), "external error");
        assert_eq!(error_class(0xF001), "additional functions");
        assert_eq!(error_class(0xFF42), "device specific");
        assert_eq!(error_class(0x0100), "unknown error class");
        assert_eq!(error_class(0xA000), "unknown error class");
        assert_eq!(error_class(0xF100), "unknown error class");
    }

    #[test]
    fn consumer_reports_and_never_panics() {
        let mut c = EmcyConsumer::new();
        let t = Instant::ZERO;
        c.handle_frame(t, &data(0x081, &[0x00, 0x10, 0x01, 0, 0, 0, 0, 0]));
        c.handle_frame(t, &data(0x0A0, &[0x00, 0x10, 0x01]));
        c.handle_frame(t, &data(0x080, &[0x00, 0x10, 0x01, 0, 0, 0, 0, 0]));
        c.handle_frame(t, &data(0x100, &[0; 8]));
        c.handle_frame(t, &Frame::remote(CanId::Standard(0x081), 8).unwrap());
        c.handle_frame(t, &Frame::new(CanId::Extended(0x081), &[0; 8]).unwrap());
        assert_eq!(
            events(&mut c),
            [
                EmcyEvent::Emergency {
                    node: node(1),
                    emcy: Emcy {
                        code: 0x1000,
                        register: 0x01,
                        manufacturer: [0; 5]
                    }
                },
                EmcyEvent::Malformed {
                    node: node(32),
                    len: 3
                }
            ]
        );
        for id in 0..=0x7FFu16 {
            for len in 0..=8 {
                c.handle_frame(t, &data(id, &[0xAA; 8][..len]));
            }
        }
        assert_eq!(events(&mut c).len(), CONSUMER_EVENTS);
        assert!(c.dropped_events() > 0);
    }

    /// A hand-written stand-in for a generated error table with 16-bit codes.
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    enum TestErrors {
        Overheat,
        Other(u16),
    }

    impl fmt::Display for TestErrors {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            f.write_str(self.name())
        }
    }

    impl ErrorTable for TestErrors {
        fn lookup(code: u64) -> Option<Self> {
            match u16::try_from(code).ok()? {
                0x4210 => Some(TestErrors::Overheat),
                other => Some(TestErrors::Other(other)),
            }
        }
        fn code(self) -> u64 {
            match self {
                TestErrors::Overheat => 0x4210,
                TestErrors::Other(c) => u64::from(c),
            }
        }
        fn is_known(self) -> bool {
            matches!(self, TestErrors::Overheat)
        }
        fn name(self) -> &'static str {
            match self {
                TestErrors::Overheat => "overheat",
                TestErrors::Other(_) => "unknown",
            }
        }
        fn text(self) -> &'static str {
            self.name()
        }
        fn reaction(self) -> Option<&'static str> {
            None
        }
        fn remedy(self) -> Option<&'static str> {
            None
        }
    }

    #[test]
    fn describe_uses_the_error_table() {
        let e = Emcy::parse(&[0x10, 0x42, 0x09, 0, 0, 0, 0, 0]).unwrap();
        assert_eq!(e.describe::<TestErrors>(), Some(TestErrors::Overheat));
        assert!(e.error_register().temperature());
        let e = Emcy::parse(&[0x34, 0x12, 0x01, 0, 0, 0, 0, 0]).unwrap();
        let d: TestErrors = e.describe().unwrap();
        assert_eq!((d.is_known(), d.code()), (false, 0x1234));
        assert_eq!(
            e.to_string(),
            "EMCY 0x1234 (generic error), error register 0x01"
        );
    }

    #[test]
    fn consumer_watches_a_set() {
        let mut c = EmcyConsumer::only(&[node(5)]);
        assert!(c.is_watched(node(5)) && !c.is_watched(node(6)));
        let e = Emcy {
            code: 0x8120,
            register: 0x11,
            manufacturer: [0; 5],
        };
        c.handle_frame(Instant::ZERO, &emcy_frame(node(6), &e));
        assert!(events(&mut c).is_empty());
        let f = emcy_frame(node(5), &e);
        assert_eq!(f, data(0x085, &[0x20, 0x81, 0x11, 0, 0, 0, 0, 0]));
        c.handle_frame(Instant::ZERO, &f);
        assert_eq!(
            events(&mut c),
            [EmcyEvent::Emergency {
                node: node(5),
                emcy: e
            }]
        );
        c.unwatch(node(5));
        c.handle_frame(Instant::ZERO, &f);
        assert!(events(&mut c).is_empty());
        c.watch(node(127));
        assert!(c.is_watched(node(127)));
    }
}
