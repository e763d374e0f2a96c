//! Frame layouts against byte sequences written by hand from the CiA 305
//! tables (not produced by the encoder), both directions, plus decoding of
//! random bytes.
//!
//! Layout of every LSS frame: byte 0 = command specifier; for the services
//! carrying a 32-bit value (switch selective, identify remote, inquire
//! identity responses, fastscan) bytes 1..=4 hold it least significant byte
//! first; configure node id: byte 1 = node id; configure bit timing: byte 1 =
//! table selector, byte 2 = table index; activate bit timing: bytes 1..=2 =
//! switch delay in ms, LSB first; configuration responses: byte 1 = error
//! code, byte 2 = spec error; fastscan: byte 5 = bit check, byte 6 = LSS sub,
//! byte 7 = LSS next. All other bytes are reserved (0).

use super::*;
use crate::CanId;

/// Requests: (hand-written bytes, the request they encode).
fn requests() -> Vec<([u8; 8], Request)> {
    use IdentityField::*;
    vec![
        // Switch state global: cs 0x04, byte 1 mode (0 waiting).
        (
            [0x04, 0x00, 0, 0, 0, 0, 0, 0],
            Request::SwitchStateGlobal(LssState::Waiting),
        ),
        // ... mode 1 configuration.
        (
            [0x04, 0x01, 0, 0, 0, 0, 0, 0],
            Request::SwitchStateGlobal(LssState::Configuration),
        ),
        // Switch state selective: cs 0x40 vendor id 0x12345678, LSB first.
        (
            [0x40, 0x78, 0x56, 0x34, 0x12, 0, 0, 0],
            Request::SwitchStateSelective(VendorId, 0x1234_5678),
        ),
        // cs 0x41 product code 0xAABBCCDD.
        (
            [0x41, 0xDD, 0xCC, 0xBB, 0xAA, 0, 0, 0],
            Request::SwitchStateSelective(ProductCode, 0xAABB_CCDD),
        ),
        // cs 0x42 revision 0x00010002.
        (
            [0x42, 0x02, 0x00, 0x01, 0x00, 0, 0, 0],
            Request::SwitchStateSelective(Revision, 0x0001_0002),
        ),
        // cs 0x43 serial 0x00000101.
        (
            [0x43, 0x01, 0x01, 0x00, 0x00, 0, 0, 0],
            Request::SwitchStateSelective(Serial, 0x101),
        ),
        // Configure node id: cs 0x11, byte 1 node id 5.
        ([0x11, 0x05, 0, 0, 0, 0, 0, 0], Request::ConfigureNodeId(5)),
        // ... 0xFF: unconfigured.
        (
            [0x11, 0xFF, 0, 0, 0, 0, 0, 0],
            Request::ConfigureNodeId(0xFF),
        ),
        // Configure bit timing: cs 0x13, byte 1 table 0, byte 2 index 3 (250 kbit/s).
        (
            [0x13, 0x00, 0x03, 0, 0, 0, 0, 0],
            Request::ConfigureBitTiming { table: 0, index: 3 },
        ),
        // Activate bit timing: cs 0x15, bytes 1..=2 delay 1000 ms = 0x03E8.
        (
            [0x15, 0xE8, 0x03, 0, 0, 0, 0, 0],
            Request::ActivateBitTiming { delay_ms: 1000 },
        ),
        // Store configuration: cs 0x17.
        ([0x17, 0, 0, 0, 0, 0, 0, 0], Request::StoreConfiguration),
        // Inquire identity: cs 0x5A vendor, 0x5B product, 0x5C revision, 0x5D serial.
        (
            [0x5A, 0, 0, 0, 0, 0, 0, 0],
            Request::InquireIdentity(VendorId),
        ),
        (
            [0x5B, 0, 0, 0, 0, 0, 0, 0],
            Request::InquireIdentity(ProductCode),
        ),
        (
            [0x5C, 0, 0, 0, 0, 0, 0, 0],
            Request::InquireIdentity(Revision),
        ),
        (
            [0x5D, 0, 0, 0, 0, 0, 0, 0],
            Request::InquireIdentity(Serial),
        ),
        // Inquire node id: cs 0x5E.
        ([0x5E, 0, 0, 0, 0, 0, 0, 0], Request::InquireNodeId),
        // Identify remote slave: cs 0x46 vendor 0x0000017A.
        (
            [0x46, 0x7A, 0x01, 0, 0, 0, 0, 0],
            Request::IdentifyRemote(RangeField::VendorId, 0x17A),
        ),
        // cs 0x47 product 0x00000002.
        (
            [0x47, 0x02, 0, 0, 0, 0, 0, 0],
            Request::IdentifyRemote(RangeField::ProductCode, 2),
        ),
        // cs 0x48 revision low 0, cs 0x49 revision high 0xFFFFFFFF.
        (
            [0x48, 0, 0, 0, 0, 0, 0, 0],
            Request::IdentifyRemote(RangeField::RevisionLow, 0),
        ),
        (
            [0x49, 0xFF, 0xFF, 0xFF, 0xFF, 0, 0, 0],
            Request::IdentifyRemote(RangeField::RevisionHigh, u32::MAX),
        ),
        // cs 0x4A serial low 0x10, cs 0x4B serial high 0x20.
        (
            [0x4A, 0x10, 0, 0, 0, 0, 0, 0],
            Request::IdentifyRemote(RangeField::SerialLow, 0x10),
        ),
        (
            [0x4B, 0x20, 0, 0, 0, 0, 0, 0],
            Request::IdentifyRemote(RangeField::SerialHigh, 0x20),
        ),
        // Identify non-configured remote slave: cs 0x4C.
        ([0x4C, 0, 0, 0, 0, 0, 0, 0], Request::IdentifyNonConfigured),
        // Fastscan confirm: cs 0x51, id 0, byte 5 bit check 0x80, sub 0, next 0.
        (
            [0x51, 0, 0, 0, 0, 0x80, 0, 0],
            Request::Fastscan(FastscanRequest::CONFIRM),
        ),
        // Fastscan step: id 0x80000000, bit check 31, sub 2, next 2.
        (
            [0x51, 0x00, 0x00, 0x00, 0x80, 0x1F, 0x02, 0x02],
            Request::Fastscan(FastscanRequest {
                id_number: 0x8000_0000,
                bit_check: 31,
                sub: 2,
                next: 2,
            }),
        ),
        // Fastscan verify of the serial: id 0x01020304, bit check 0, sub 3, next 0.
        (
            [0x51, 0x04, 0x03, 0x02, 0x01, 0x00, 0x03, 0x00],
            Request::Fastscan(FastscanRequest {
                id_number: 0x0102_0304,
                bit_check: 0,
                sub: 3,
                next: 0,
            }),
        ),
    ]
}

/// Responses: (hand-written bytes, the response they encode).
fn responses() -> Vec<([u8; 8], Response)> {
    use IdentityField::*;
    vec![
        // Switch state selective response: cs 0x44.
        ([0x44, 0, 0, 0, 0, 0, 0, 0], Response::SwitchStateSelective),
        // Configure node id response: cs 0x11, byte 1 error 0, byte 2 spec 0.
        (
            [0x11, 0, 0, 0, 0, 0, 0, 0],
            Response::ConfigureNodeId { error: 0, spec: 0 },
        ),
        // ... error 1: node id out of range.
        (
            [0x11, 0x01, 0, 0, 0, 0, 0, 0],
            Response::ConfigureNodeId { error: 1, spec: 0 },
        ),
        // Configure bit timing response: cs 0x13, error 0xFF, spec 0x07.
        (
            [0x13, 0xFF, 0x07, 0, 0, 0, 0, 0],
            Response::ConfigureBitTiming {
                error: 0xFF,
                spec: 7,
            },
        ),
        // Store configuration response: cs 0x17, error 2 (storage media).
        (
            [0x17, 0x02, 0, 0, 0, 0, 0, 0],
            Response::StoreConfiguration { error: 2, spec: 0 },
        ),
        // Inquire identity responses: cs 0x5A..=0x5D, value LSB first.
        (
            [0x5A, 0x7A, 0x01, 0, 0, 0, 0, 0],
            Response::InquireIdentity(VendorId, 0x17A),
        ),
        (
            [0x5B, 0x44, 0x33, 0x22, 0x11, 0, 0, 0],
            Response::InquireIdentity(ProductCode, 0x1122_3344),
        ),
        (
            [0x5C, 0x01, 0, 0x02, 0, 0, 0, 0],
            Response::InquireIdentity(Revision, 0x0002_0001),
        ),
        (
            [0x5D, 0xEF, 0xBE, 0xAD, 0xDE, 0, 0, 0],
            Response::InquireIdentity(Serial, 0xDEAD_BEEF),
        ),
        // Inquire node id response: cs 0x5E, byte 1 node id 127.
        ([0x5E, 0x7F, 0, 0, 0, 0, 0, 0], Response::InquireNodeId(127)),
        // Identify slave: cs 0x4F; identify non-configured slave: cs 0x50.
        ([0x4F, 0, 0, 0, 0, 0, 0, 0], Response::IdentifySlave),
        (
            [0x50, 0, 0, 0, 0, 0, 0, 0],
            Response::IdentifyNonConfiguredSlave,
        ),
    ]
}

#[test]
fn request_layouts() {
    for (bytes, request) in requests() {
        assert_eq!(Request::parse(&bytes), Some(request), "{bytes:02X?}");
        assert_eq!(request.encode(), bytes, "{request:?}");
        let frame = request.to_frame();
        assert_eq!(frame.id(), CanId::Standard(0x7E5));
        assert_eq!(frame.data(), &bytes);
        assert_eq!(Request::from_frame(&frame), Some(request));
    }
}

#[test]
fn response_layouts() {
    for (bytes, response) in responses() {
        assert_eq!(Response::parse(&bytes), Some(response), "{bytes:02X?}");
        assert_eq!(response.encode(), bytes, "{response:?}");
        let frame = response.to_frame();
        assert_eq!(frame.id(), CanId::Standard(0x7E4));
        assert_eq!(frame.data(), &bytes);
        assert_eq!(Response::from_frame(&frame), Some(response));
    }
}

#[test]
fn reserved_bytes_are_ignored() {
    assert_eq!(
        Request::parse(&[0x17, 1, 2, 3, 4, 5, 6, 7]),
        Some(Request::StoreConfiguration)
    );
    assert_eq!(
        Request::parse(&[0x40, 1, 0, 0, 0, 0xAA, 0xBB, 0xCC]),
        Some(Request::SwitchStateSelective(IdentityField::VendorId, 1))
    );
    assert_eq!(
        Response::parse(&[0x4F, 9, 9, 9, 9, 9, 9, 9]),
        Some(Response::IdentifySlave)
    );
}

#[test]
fn malformed_frames_are_refused() {
    // Wrong length.
    assert_eq!(Request::parse(&[0x04, 0x01, 0, 0, 0, 0, 0]), None);
    assert_eq!(Request::parse(&[0x04, 0x01, 0, 0, 0, 0, 0, 0, 0]), None);
    assert_eq!(Request::parse(&[]), None);
    assert_eq!(Response::parse(&[0x44]), None);
    // Reserved mode, unknown specifiers.
    assert_eq!(Request::parse(&[0x04, 0x02, 0, 0, 0, 0, 0, 0]), None);
    for code in [0x00, 0x05, 0x12, 0x44, 0x4D, 0x4F, 0x50, 0x52, 0x5F, 0xFF] {
        assert_eq!(
            Request::parse(&[code, 0, 0, 0, 0, 0, 0, 0]),
            None,
            "{code:#x}"
        );
    }
    for code in [0x04, 0x40, 0x43, 0x15, 0x46, 0x4C, 0x51, 0x59, 0x5F] {
        assert_eq!(
            Response::parse(&[code, 0, 0, 0, 0, 0, 0, 0]),
            None,
            "{code:#x}"
        );
    }
    // Fastscan: bit check 32 and 0x81, sub 4, next 4.
    for (bit, sub, next) in [(32, 0, 0), (0x81, 0, 0), (0, 4, 0), (0, 0, 4)] {
        assert_eq!(Request::parse(&[0x51, 0, 0, 0, 0, bit, sub, next]), None);
    }
    // Wrong COB-ID, direction, length or a remote frame.
    let store = [0x17, 0, 0, 0, 0, 0, 0, 0];
    let on = |id: u16, data: &[u8]| Frame::new(CanId::Standard(id), data).unwrap();
    assert_eq!(Request::from_frame(&on(0x7E4, &store)), None);
    assert_eq!(Response::from_frame(&on(0x7E5, &store)), None);
    assert_eq!(Request::from_frame(&on(0x7E5, &store[..7])), None);
    assert_eq!(
        Request::from_frame(&Frame::new(CanId::Extended(0x7E5), &store).unwrap()),
        None
    );
    assert_eq!(
        Request::from_frame(&Frame::remote(CanId::Standard(0x7E5), 8).unwrap()),
        None
    );
}

/// A small deterministic generator (xorshift64*), so the test needs no
/// dependency.
fn random_bytes(state: &mut u64, out: &mut [u8]) {
    for byte in out {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        *byte = (state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 56) as u8;
    }
}

#[test]
fn random_bytes_never_panic_and_round_trip() {
    let mut state = 0x9E37_79B9_7F4A_7C15;
    let mut buf = [0u8; 10];
    for i in 0..200_000usize {
        let len = i % 11;
        let data = &mut buf[..len];
        random_bytes(&mut state, data);
        // Bias byte 0 towards the LSS specifiers so every branch is hit.
        if let Some(first) = data.first_mut()
            && i % 2 == 0
        {
            *first = 0x40 + (*first % 0x20);
        }
        if let Some(request) = Request::parse(data) {
            assert_eq!(len, 8);
            // Decoding the encoding gives the same request back; fields
            // that are not reserved survive byte for byte.
            let encoded = request.encode();
            assert_eq!(Request::parse(&encoded), Some(request));
            assert_eq!(encoded.first(), data.first());
        }
        if let Some(response) = Response::parse(data) {
            assert_eq!(len, 8);
            let encoded = response.encode();
            assert_eq!(Response::parse(&encoded), Some(response));
            assert_eq!(encoded.first(), data.first());
        }
    }
}
