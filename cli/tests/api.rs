//! `eds2rust api`: the listing of the generated API, as the library gives it.

mod common;

use common::{example, run, seed, temp_file};

#[test]
fn api_lists_the_generated_api_or_errors() {
    let linak = seed("linak_techline");
    let (code, stdout, stderr) = run(&["api", &linak]);
    assert_eq!(code, 0, "{stderr}");
    let options = eds2rust::read::Options::default();
    let library = eds2rust::build::api_listing_files(linak.as_ref(), &[], &options);
    assert_eq!(
        stdout,
        library.expect("lists").text,
        "the library's listing"
    );
    assert!(stdout.contains("\npdo::Tpdo1Feedback\t0x1A00\ttpdo 1\t8 bytes\tposition@0..16:"));

    // An overlay changes the line of the entry it changes, and only that.
    let overlay = temp_file(
        "api_overlay.yaml",
        "format: 1\nmodify:\n  - { index: 0x6060, access: ro }\n",
    );
    let (_, before, _) = run(&["api", &example()]);
    let (code, after, stderr) = run(&["api", "--overlay", &overlay, &example()]);
    assert_eq!(code, 0, "{stderr}");
    let changed: Vec<_> = before
        .lines()
        .zip(after.lines())
        .filter(|(a, b)| a != b)
        .collect();
    let line = "od::ModesOfOperation\t0x6060\tod::ModesOfOperationValue\t";
    assert_eq!(
        changed,
        [(&*format!("{line}rw\t-\tpdo"), &*format!("{line}ro\t-\tpdo"))]
    );

    // Warnings on stderr and the listing on stdout; errors: exit 1, no listing.
    let warn = &temp_file(
        "api_warn.eds",
        "[1000]\nParameterName=Device type\nDataType=0x0007\nAccessType=ro\nDefaultValue=017\nDefaultValue=0x10\n",
    );
    let listing = "od::DeviceType\t0x1000\tu32\tro\t-\t-\n";
    let (code, stdout, stderr) = run(&["api", warn]);
    assert_eq!((code, stdout.as_str()), (0, listing), "{stderr}");
    assert!(stderr.contains("warning[eds::duplicate-key]"), "{stderr}");
    let allow = [
        "--allow",
        "eds::duplicate-key",
        "--allow",
        "eds::unlisted-object",
    ];
    let (code, stdout, stderr) = run(&[&["api", "--strict"], &allow[..], &[warn]].concat());
    assert_eq!((code, stdout.as_str(), stderr.as_str()), (0, listing, ""));
    let bad = &temp_file(
        "api_bad.yaml",
        "format: 1\nobjects:\n  - { index: 0x2000, name: A, type: UINT16, access: rw }\n",
    );
    for args in [
        vec!["api", "--strict", warn],
        vec!["api", "--deny", "eds::duplicate-key", warn],
        vec!["api", bad],
        vec!["api", "--overlay", bad, &example()],
    ] {
        let (code, stdout, stderr) = run(&args);
        assert_eq!((code, stdout.as_str()), (1, ""), "{args:?}: {stderr}");
        assert!(stderr.contains("not listed: "), "{stderr}");
    }
    assert_eq!(run(&["api"]).0, 2, "no input is a usage error");
    assert_eq!(run(&["api", "--allow", "eds::no-such-rule", warn]).0, 2);
}
