//! Replays the committed fuzz corpora (codegen/fuzz/corpus/<target>/, the
//! minimized output of the cargo-fuzz campaign) through the bodies of the
//! fuzz targets on the stable toolchain, without a fuzzer. A missing or empty
//! corpus directory fails the test. See docs/fuzzing.md.

mod fuzz_checks;

eds2rust_fuzz_replay::replay_tests! {
    eds_reader_corpus: "eds_reader" => fuzz_checks::eds_reader,
    yaml_reader_corpus: "yaml_reader" => fuzz_checks::yaml_reader,
    bus_reader_corpus: "bus_reader" => fuzz_checks::bus_reader,
}
