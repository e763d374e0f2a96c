//! The generated code never allocates: decoding and encoding every default
//! PDO of the three seed devices (valid frames and the error paths of short
//! and long frames), and the value types' methods (`value()`,
//! `from_value()`, `text()`, `state()`, `Display` of the error enums into a
//! fixed-size buffer), run under a global allocator that counts.
//!
//! The allocator counts only on the thread that armed it, so the test
//! harness (other test threads, output capture) does not disturb the count.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::fmt::Write as _;
use std::hint::black_box;

use eds2rust_drivers::{interroll_ec5000bi as ir, linak_techline as lk, zimmer_acs as zm};
use eds2rust_runtime::od::{Pdo, PdoLengthError, Scaled};

struct Counting;

thread_local! {
    static ARMED: Cell<bool> = const { Cell::new(false) };
    static COUNT: Cell<usize> = const { Cell::new(0) };
}

fn note() {
    // `try_with`: the allocator also runs while thread-locals are torn down.
    let _ = ARMED.try_with(|armed| {
        if armed.get() {
            COUNT.with(|c| c.set(c.get() + 1));
        }
    });
}

// SAFETY: every call is forwarded to `System` unchanged; counting touches
// only const-initialised thread-locals without destructors (no allocation).
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note();
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note();
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// The number of allocations `f` makes on this thread.
fn allocations(f: impl FnOnce()) -> usize {
    COUNT.with(|c| c.set(0));
    ARMED.with(|a| a.set(true));
    f();
    ARMED.with(|a| a.set(false));
    COUNT.with(Cell::get)
}

/// A fixed-size `fmt::Write` sink: formatting into it cannot allocate.
struct Buf {
    data: [u8; 4096],
    len: usize,
}

impl Buf {
    fn new() -> Buf {
        Buf {
            data: [0; 4096],
            len: 0,
        }
    }
    fn as_str(&self) -> &str {
        std::str::from_utf8(&self.data[..self.len]).expect("UTF-8")
    }
}

impl std::fmt::Write for Buf {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        let end = self.len + s.len();
        let dst = self.data.get_mut(self.len..end).ok_or(std::fmt::Error)?;
        dst.copy_from_slice(s.as_bytes());
        self.len = end;
        Ok(())
    }
}

/// Frames per PDO: pseudo-random (xorshift64), plus every byte pattern of the first two bytes.
const FRAMES: u64 = 4096;

/// Decodes `FRAMES` frames of the right length and every length from 0 to 9
/// that is wrong, and encodes every decoded value both ways; returns a
/// checksum so that nothing is optimised away.
fn exercise<P: Pdo + Copy + PartialEq + std::fmt::Debug>(
    seed: u64,
    encode: impl Fn(&P) -> [u8; 8],
) -> u64 {
    let mut state = seed | 1;
    let mut sum = 0u64;
    for i in 0..FRAMES {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let mut bytes = state.to_le_bytes();
        bytes[..2].copy_from_slice(&(i as u16).wrapping_mul(0x3F1).to_le_bytes());
        let frame = &black_box(bytes)[..P::LEN];
        let value = P::decode(frame).expect("a frame of the right length decodes");
        let mut out = [0u8; 8];
        assert_eq!(value.encode_into(&mut out), P::LEN);
        assert_eq!(&out[..P::LEN], frame, "encode(decode(frame)) == frame");
        assert_eq!(&encode(&value)[..P::LEN], frame);
        assert_eq!(P::decode(&out[..P::LEN]), Ok(value));
        sum = sum.wrapping_add(u64::from(out[0]));
    }
    for len in (0..=9).filter(|&n| n != P::LEN) {
        let frame = black_box([0xA5u8; 9]);
        let error = P::decode(&frame[..len]).expect_err("a frame of the wrong length is an error");
        let expected = PdoLengthError {
            expected: P::LEN,
            actual: len,
        };
        assert_eq!(error, expected);
        let mut buf = Buf::new();
        write!(buf, "{error}").expect("fits");
        sum = sum.wrapping_add(buf.len as u64);
    }
    sum
}

/// The inherent `encode` of a generated PDO struct, padded to 8 bytes.
macro_rules! enc {
    ($t:ty) => {
        |p: &$t| {
            let mut out = [0u8; 8];
            let bytes = p.encode();
            out[..bytes.len()].copy_from_slice(&bytes);
            out
        }
    };
}

/// A `#[derive(Pdo)]` struct: 12 bits of the statusword, 4 signed bits of
/// the mode display, the position; every one of its 48 bits a field's.
#[derive(eds2rust_drivers::runtime::Pdo, Debug, Clone, Copy, PartialEq)]
#[pdo(tpdo = 4, runtime = eds2rust_drivers::runtime)]
struct Packed {
    #[pdo(entry = ir::od::Statusword, bits = 12)]
    status: <ir::od::Statusword as eds2rust_drivers::runtime::od::Entry>::Value,
    #[pdo(entry = ir::od::ModesOfOperationDisplay, bits = 4)]
    mode: ir::od::ModesOfOperationDisplayValue,
    #[pdo(entry = ir::od::PositionActualValue)]
    position: ir::od::PositionActualValueValue,
}

fn all_pdos() -> u64 {
    let mut sum = 0;
    sum += exercise::<Packed>(15, enc!(Packed));
    sum += exercise::<lk::pdo::Rpdo1Command>(1, enc!(lk::pdo::Rpdo1Command));
    sum += exercise::<lk::pdo::Tpdo1Feedback>(2, enc!(lk::pdo::Tpdo1Feedback));
    sum += exercise::<lk::pdo::Tpdo2ParallelFeedback>(3, enc!(lk::pdo::Tpdo2ParallelFeedback));
    sum += exercise::<zm::pdo::Rpdo1ControlAndTargetPosition>(
        4,
        enc!(zm::pdo::Rpdo1ControlAndTargetPosition),
    );
    sum += exercise::<zm::pdo::Rpdo2ProfileVelocity>(5, enc!(zm::pdo::Rpdo2ProfileVelocity));
    sum += exercise::<zm::pdo::Tpdo1StatusAndPosition>(6, enc!(zm::pdo::Tpdo1StatusAndPosition));
    sum += exercise::<zm::pdo::Tpdo2Velocity>(7, enc!(zm::pdo::Tpdo2Velocity));
    sum += exercise::<zm::pdo::Tpdo3FollowingErrorAndTorque>(
        8,
        enc!(zm::pdo::Tpdo3FollowingErrorAndTorque),
    );
    sum += exercise::<ir::pdo::Rpdo1VelocityCommand>(9, enc!(ir::pdo::Rpdo1VelocityCommand));
    sum += exercise::<ir::pdo::Rpdo2PositionCommand>(10, enc!(ir::pdo::Rpdo2PositionCommand));
    sum += exercise::<ir::pdo::Rpdo3TargetVelocityCommand>(
        11,
        enc!(ir::pdo::Rpdo3TargetVelocityCommand),
    );
    sum += exercise::<ir::pdo::Tpdo1Status>(12, enc!(ir::pdo::Tpdo1Status));
    sum += exercise::<ir::pdo::Tpdo2Position>(13, enc!(ir::pdo::Tpdo2Position));
    sum += exercise::<ir::pdo::Tpdo3Velocity>(14, enc!(ir::pdo::Tpdo3Velocity));
    sum
}

/// Value types: numbers with units, named values, bit fields, states, error
/// tables and their `Display` into a fixed-size buffer.
fn value_types(buf: &mut Buf) -> f64 {
    use lk::od::command;
    let mut sum = 0.0;
    let position = command::PositionNumber::from_value(black_box(12.3)).expect("in range");
    sum += position.value() + f64::from(position.to_raw());
    assert_eq!(
        command::PositionNumber::from_value(black_box(f64::NAN)),
        None
    );
    let stop = command::PositionValue::from_raw(black_box(0xFB03));
    assert_eq!(stop, command::PositionValue::STOP);
    assert_eq!(stop.kind(), command::PositionKind::Stop);
    sum += (stop.text().len() + stop.name().len()) as f64;
    let fb = lk::pdo::Tpdo1Feedback::decode(&black_box([0x1A, 0, 6, 0x88, 0, 0x31, 0, 0xC0]))
        .expect("trace frame");
    if let Some(n) = fb.position.number() {
        sum += n.value();
    }
    sum += fb.current.text().len() as f64 + fb.aux_inputs.input_level_4_value();
    sum += f64::from(u8::from(fb.status_flags.running_out()));
    let error = lk::errors::LinakErrorsCode::from_raw(black_box(1)).kind();
    write!(buf, "{error}; {}", error.remedy().unwrap_or("-")).expect("fits");
    write!(
        buf,
        "|{}",
        lk::errors::ParallelErrorsCode::from_raw(black_box(2))
    )
    .expect("fits");
    write!(buf, "|{}", lk::errors::Emcy::from_code(black_box(0x3211))).expect("fits");

    let torque = zm::od::TorqueActualValueValue::from_value(black_box(-12.0)).expect("in range");
    sum += torque.value();
    let status = zm::od::StatuswordValue::from_raw(black_box(0x0627));
    assert_eq!(
        status.state(),
        Some(zm::od::StatuswordState::OperationEnabled)
    );
    write!(buf, "|{:?} {:.1}", status.state(), torque.value()).expect("fits");
    write!(
        buf,
        "|{}",
        zm::errors::ZimmerErrors::from_code(black_box(0x1001))
    )
    .expect("fits");

    let mode = ir::od::ModesOfOperationValue::from_raw(black_box(3));
    sum += mode.text().len() as f64;
    let velocity = ir::od::ProfileVelocityValue::from_value(black_box(1500.0)).expect("in range");
    sum += velocity.value();
    write!(buf, "|{}", ir::errors::Emcy::from_code(black_box(0x3210))).expect("fits");
    write!(
        buf,
        "|{}",
        ir::errors::SdoAbort::from_code(black_box(0x0602_0000))
    )
    .expect("fits");
    sum
}

#[test]
fn the_counter_counts() {
    assert_eq!(
        allocations(|| drop(black_box(Vec::<u8>::with_capacity(16)))),
        1
    );
    assert_eq!(allocations(|| drop(black_box(format!("{}", 7)))), 1);
}

#[test]
fn decoding_and_encoding_every_pdo_allocates_nothing() {
    let mut sum = 0;
    let count = allocations(|| sum = black_box(all_pdos()));
    assert_eq!(count, 0, "allocations while decoding and encoding PDOs");
    assert_ne!(sum, 0);
}

#[test]
fn value_types_and_error_display_allocate_nothing() {
    let mut buf = Buf::new();
    let mut sum = 0.0;
    let count = allocations(|| sum = black_box(value_types(&mut buf)));
    assert_eq!(count, 0, "allocations in value-type methods and Display");
    assert!(sum.is_finite());
    let text = buf.as_str();
    assert!(text.starts_with("0x01 "), "{text}");
    assert!(
        text.contains("Send Stop (0xFB03) or Clear error (0xFB00)"),
        "{text}"
    );
}
