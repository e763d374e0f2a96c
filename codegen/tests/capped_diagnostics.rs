//! Repeated diagnostics of one rule in one file are capped (docs/diagnostics.md,
//! "Repeated diagnostics"): a generated file with more than `CAP` duplicate
//! keys and unknown sections keeps the first `CAP` of each rule and one
//! summary per rule saying how many were left out. The snapshot shows the
//! first diagnostic of each rule and the summaries as rendered.

use eds2rust::diag::{CAP, Diagnostics};
use eds2rust::eds::{Options, read_bytes};

const FILE: &str = "generated/capped.eds";
const DUPLICATES: usize = 130;
const UNKNOWN: usize = 105;

fn input() -> String {
    let mut text = String::from(
        "[DeviceInfo]\nVendorName=v\n[MandatoryObjects]\nSupportedObjects=1\n1=0x1000\n\
         [1000]\nParameterName=Device type\nObjectType=0x7\nDataType=0x0007\nAccessType=ro\n\
         DefaultValue=0\nPDOMapping=0\n[Comments]\nLines=1\n",
    );
    for i in 0..=DUPLICATES {
        text.push_str(&format!("Line1=comment {i}\n"));
    }
    for i in 1..=UNKNOWN {
        text.push_str(&format!("[Junk{i}]\n"));
    }
    text
}

#[test]
fn repeated_diagnostics_are_capped_with_a_summary() {
    let text = input();
    let loaded = read_bytes(FILE, text.as_bytes(), &Options::default());
    let d = &loaded.diagnostics;
    assert_eq!(d.len(), 2 * CAP + 2, "{CAP} of each rule and two summaries");
    let of = |code: &str| d.iter().filter(|x| x.code == code).count();
    assert_eq!(of("eds::duplicate-key"), CAP + 1);
    assert_eq!(of("eds::unknown-section"), CAP + 1);
    // The later value still wins.
    assert_eq!(
        loaded.device.as_ref().unwrap().comments,
        [format!("comment {DUPLICATES}")]
    );

    // The first of each rule and the summaries, rendered.
    let mut shown = Diagnostics::new();
    shown.add_source(FILE, &text);
    let mut seen = Vec::new();
    for x in d.iter() {
        let summary = x.message.contains("were left out");
        if summary || !seen.contains(&x.code) {
            seen.push(x.code);
            shown.push(x.clone());
        }
    }
    let rendered = format!(
        "{}\n{} errors, {} warnings\n",
        shown.render(),
        d.error_count(),
        d.warning_count()
    );
    insta::assert_snapshot!(rendered);

    // Allowing a rule drops its summary too, counting every warning it stood for.
    let mut options = Options::default();
    options.levels.allow("eds::duplicate-key", "test");
    let allowed = read_bytes(FILE, text.as_bytes(), &options);
    assert_eq!(allowed.diagnostics.allowed_count(), DUPLICATES);
    // Strict turns the summary into an error as it does the rest.
    let strict = read_bytes(FILE, text.as_bytes(), &Options::strict());
    assert_eq!(strict.diagnostics.error_count(), 2 * CAP + 2);
}
