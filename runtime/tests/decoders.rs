//! Property tests over every frame decoder and protocol core: the bodies of
//! the cargo-fuzz targets (tests/fuzz_checks) run here on random input in CI,
//! plus inputs shaped like the frames each decoder expects.

mod fuzz_checks;

use proptest::prelude::*;

/// Random bytes, or frames on the ids the cores listen to.
fn input() -> impl Strategy<Value = Vec<u8>> {
    let frame = (
        prop_oneof![
            Just(0x000u16),
            Just(0x080),
            0x081u16..0x100,
            0x580u16..0x680,
            0x701u16..0x780,
            any::<u16>()
        ],
        0u8..=8,
        0u8..16,
        proptest::collection::vec(any::<u8>(), 8),
        any::<bool>(),
    )
        .prop_map(|(id, len, step, data, remote)| {
            let head = (id & 0x7FF) | if remote && id % 7 == 0 { 0x8000 } else { 0 };
            let mut bytes = head.to_le_bytes().to_vec();
            bytes.push(step << 4 | len);
            bytes.extend_from_slice(&data[..usize::from(len)]);
            bytes
        });
    prop_oneof![
        proptest::collection::vec(any::<u8>(), 0..256),
        proptest::collection::vec(frame, 0..40).prop_map(|frames| frames.concat()),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2048, ..ProptestConfig::default() })]

    #[test]
    fn sdo_request(data in proptest::collection::vec(any::<u8>(), 0..10)) {
        fuzz_checks::sdo_request(&data);
    }

    #[test]
    fn sdo_response(data in proptest::collection::vec(any::<u8>(), 0..10)) {
        fuzz_checks::sdo_response(&data);
    }

    #[test]
    fn block_segment(data in proptest::collection::vec(any::<u8>(), 0..10)) {
        fuzz_checks::block_segment(&data);
    }

    #[test]
    fn sdo_server(data in input()) {
        fuzz_checks::sdo_server(&data);
    }

    #[test]
    fn sdo_client(data in input()) {
        fuzz_checks::sdo_client(&data);
    }

    #[test]
    fn nmt_and_error_control(data in input()) {
        fuzz_checks::nmt_and_error_control(&data);
    }

    #[test]
    fn emcy_and_sync(data in input()) {
        fuzz_checks::emcy_and_sync(&data);
    }

    #[test]
    fn lss_frames(data in prop_oneof![
        proptest::collection::vec(any::<u8>(), 8),
        input(),
    ]) {
        fuzz_checks::lss_frames(&data);
    }

    #[test]
    fn pdo_receiver(data in input()) {
        fuzz_checks::pdo_receiver(&data);
    }

    #[test]
    fn candump_line(text in "(\\([0-9]{1,10}\\.[0-9]{0,9}\\) )?([a-z0-9]{1,6} )?[0-9A-Fa-f]{3,8}#(R[0-9]?|[0-9A-Fa-f.]{0,20})") {
        fuzz_checks::candump_line(text.as_bytes());
    }

    #[test]
    fn candump_text_line(text in " *[a-z0-9]{1,6} +[0-9A-F]{3,8} +\\[[0-9]\\]( +[0-9A-F]{2}){0,9}( +remote request)?") {
        fuzz_checks::candump_line(text.as_bytes());
    }

    #[test]
    fn candump_bytes(data in proptest::collection::vec(any::<u8>(), 0..64)) {
        fuzz_checks::candump_line(&data);
    }
}
