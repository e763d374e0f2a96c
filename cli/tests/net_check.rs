//! `eds2rust net check`: exit codes, levels and the bus load limit on the
//! fixtures of tests/networks/check.

mod common;

use common::run;

fn fixture(rule: &str) -> String {
    format!(
        "{}/../tests/networks/check/{rule}/bus.yml",
        env!("CARGO_MANIFEST_DIR")
    )
}

#[test]
fn net_check_exit_codes_and_levels() {
    // Errors: exit 1, each with the bus file's line and its fix.
    let (code, stdout, _) = run(&["net", "check", &fixture("cob-id-collision")]);
    assert_eq!(code, 1, "{stdout}");
    assert!(stdout.contains("error[net::cob-id-collision]"), "{stdout}");
    assert!(stdout.contains("cob-id-collision/bus.yml:14:"), "{stdout}");
    assert!(stdout.contains("bus load at 1000 kbit/s"), "{stdout}");
    assert!(stdout.contains("2 nodes, 2 errors, 0 warnings"), "{stdout}");

    // A warning only: 0, 1 with --strict or --deny, 0 and no warning with --allow.
    let restricted = fixture("cob-id-restricted");
    assert_eq!(run(&["net", "check", &restricted]).0, 0);
    assert_eq!(run(&["net", "check", "--strict", &restricted]).0, 1);
    for (level, status, says) in [
        ("--deny", 1, "is denied by --deny"),
        ("--allow", 0, "0 errors, 0 warnings"),
    ] {
        let rule = "net::cob-id-restricted";
        let (code, stdout, _) = run(&["net", "check", level, rule, &restricted]);
        assert_eq!(code, status, "{level}: {stdout}");
        assert!(stdout.contains(says), "{level}: {stdout}");
    }

    // The bus load limit.
    let load = fixture("bus-load");
    let (code, stdout, _) = run(&["net", "check", &load]);
    assert_eq!(code, 0, "{stdout}");
    assert!(stdout.contains("warning[net::bus-load]"), "{stdout}");
    let (_, stdout, _) = run(&["net", "check", "--max-bus-load", "400", &load]);
    assert!(!stdout.contains("net::bus-load"), "{stdout}");

    // Usage errors: 2.
    assert_eq!(run(&["net", "check", "--max-bus-load", "-1", &load]).0, 2);
    assert_eq!(
        run(&["net", "check", "--allow", "net::no-such-rule", &load]).0,
        2
    );
    assert_eq!(run(&["net", "check"]).0, 2);
}
