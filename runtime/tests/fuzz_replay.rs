//! Replays the committed fuzz corpora (runtime/fuzz/corpus/<target>/, the
//! minimized output of the cargo-fuzz campaign) through the bodies of the
//! fuzz targets on the stable toolchain, without a fuzzer. A missing or empty
//! corpus directory fails the test. See docs/fuzzing.md.

mod fuzz_checks;

eds2rust_fuzz_replay::replay_tests! {
    sdo_request_corpus: "sdo_request" => fuzz_checks::sdo_request,
    sdo_response_corpus: "sdo_response" => fuzz_checks::sdo_response,
    block_segment_corpus: "block_segment" => fuzz_checks::block_segment,
    sdo_server_corpus: "sdo_server" => fuzz_checks::sdo_server,
    sdo_client_corpus: "sdo_client" => fuzz_checks::sdo_client,
    nmt_and_error_control_corpus: "nmt_and_error_control" => fuzz_checks::nmt_and_error_control,
    emcy_and_sync_corpus: "emcy_and_sync" => fuzz_checks::emcy_and_sync,
    lss_frames_corpus: "lss_frames" => fuzz_checks::lss_frames,
    pdo_receiver_corpus: "pdo_receiver" => fuzz_checks::pdo_receiver,
    candump_line_corpus: "candump_line" => fuzz_checks::candump_line,
}
