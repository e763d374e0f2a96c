//! `eds2rust net boot --simulate`: the seed machine (eds/machine/bus.yml)
//! and the fault-matrix network (tests/networks/boot/matrix.yml) booted
//! against their own simulation, in virtual time: the table is the same on
//! every run and locked by a snapshot; exit codes and usage errors.

mod common;

use common::{root, row};

/// Runs the binary in the workspace root (paths in the output are as
/// given): exit code, stdout, stderr.
fn run(args: &[&str]) -> (i32, String, String) {
    common::run_in(&root(), args)
}

/// `eds2rust net boot --simulate ARGS...` in the workspace root.
fn simulate(args: &[&str]) -> (i32, String, String) {
    run(&[&["net", "boot", "--simulate"][..], args].concat())
}

/// `net boot --simulate --run --duration DURATION` of the fault-matrix
/// network with `fault`, then `more` arguments.
fn run_matrix(fault: &str, duration: &str, more: &[&str]) -> (i32, String, String) {
    let args = ["--fault", fault, "--run", "--duration", duration];
    simulate(&[&args[..], more, &["tests/networks/boot/matrix.yml"]].concat())
}

#[test]
fn the_seed_machine_boots_in_its_simulation() {
    let (code, stdout, stderr) = simulate(&["eds/machine/bus.yml"]);
    assert_eq!(code, 0, "{stdout}{stderr}");
    insta::assert_snapshot!("net_boot_seed_machine", stdout);
}

#[test]
fn every_slave_row_says_what_its_boot_did() {
    let (code, stdout, stderr) = simulate(&["tests/networks/boot/matrix.yml"]);
    assert_eq!(code, 0, "{stdout}{stderr}");
    let rows: Vec<Vec<&str>> = stdout
        .lines()
        .filter(|l| l.starts_with('|'))
        .map(|l| l.trim_matches('|').split('|').map(str::trim).collect())
        .collect();
    assert_eq!(
        rows,
        [
            vec![
                "node",
                "name",
                "mandatory",
                "identity",
                "configuration",
                "state",
                "time",
                "boot error"
            ],
            vec![
                "2",
                "left",
                "yes",
                "ok",
                "4 entries written",
                "operational",
                "0.050 s",
                ""
            ],
            vec![
                "3",
                "right",
                "no",
                "ok",
                "4 entries written",
                "operational",
                "0.050 s",
                ""
            ],
        ],
        "{stdout}"
    );
    assert!(
        stdout.ends_with(
            "tests/networks/boot/matrix.yml: 2 of 2 slaves operational in 0.050 s (simulated time)\n"
        ),
        "{stdout}"
    );
}

/// The mandatory slave missing: its boot fails with status B when the
/// boot time (1 s) is over, the optional one boots; exit status 1 and a
/// summary naming the slave, its node and the status.
#[test]
fn a_missing_mandatory_slave_fails_the_boot_with_status_b() {
    let (code, stdout, stderr) =
        simulate(&["--fault", "left:missing", "tests/networks/boot/matrix.yml"]);
    assert_eq!(code, 1, "{stdout}{stderr}");
    let row = |node: &str| row(&stdout, node);
    assert_eq!(
        row("2"),
        [
            "2",
            "left",
            "yes",
            "-",
            "-",
            "failed",
            "1.000 s",
            "node 2: boot error B: the node did not answer the read of its device type (0x1000) (0x1000 sub 0)"
        ],
        "{stdout}"
    );
    assert_eq!(row("3")[5], "operational", "{stdout}");
    let summary = stdout.lines().last().unwrap_or_default();
    assert_eq!(
        summary,
        "tests/networks/boot/matrix.yml: the network did not boot: left: node 2: boot error B: \
         the node did not answer the read of its device type (0x1000) (0x1000 sub 0)"
    );

    // The optional slave missing: the network runs (exit status 0), the
    // summary names the slave that is not up.
    let (code, stdout, stderr) =
        simulate(&["--fault", "3:missing", "tests/networks/boot/matrix.yml"]);
    assert_eq!(code, 0, "{stdout}{stderr}");
    assert!(
        stdout.ends_with("optional slaves not up: right (node 3) B\n"),
        "{stdout}"
    );

    // A wrong identity: status O, with the expected and found values.
    let (code, stdout, _) =
        simulate(&["--fault", "left:serial=5", "tests/networks/boot/matrix.yml"]);
    assert_eq!(code, 1, "{stdout}");
    assert!(
        stdout.contains("| wrong ") && stdout.contains("expected 0x00C0FFEE, found 0x00000005"),
        "{stdout}"
    );
}

#[test]
fn json_has_the_outcome_and_every_slave() {
    let (code, stdout, stderr) = simulate(&["--format", "json", "tests/networks/boot/matrix.yml"]);
    assert_eq!(code, 0, "{stdout}{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("one JSON object");
    assert_eq!(v["running"], true);
    assert_eq!(v["decided"], true);
    assert_eq!(v["simulated"], true);
    let slaves = v["slaves"].as_array().expect("slaves");
    assert_eq!(slaves.len(), 2);
    assert_eq!(slaves[0]["node"], 2);
    assert_eq!(slaves[0]["name"], "left");
    assert_eq!(slaves[0]["state"], "operational");
    assert_eq!(slaves[0]["entries_written"], 4);
    assert_eq!(slaves[0]["error"], serde_json::Value::Null);
}

#[test]
fn usage_and_input_errors() {
    let bus = "tests/networks/boot/matrix.yml";
    // Neither --iface nor --simulate, or both: usage errors.
    assert_eq!(run(&["net", "boot", bus]).0, 2);
    assert_eq!(simulate(&["--iface", "vcan0", bus]).0, 2);
    assert_eq!(simulate(&["--timeout", "0", bus]).0, 2);
    // A bus file with errors is not booted.
    let (code, _, stderr) = simulate(&["tests/networks/check/node-id/bus.yml"]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("not booted:"), "{stderr}");
    // An interface that is not there: 1, naming it.
    let (code, _, stderr) = run(&["net", "boot", "--iface", "eds2rust-none0", bus]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("eds2rust-none0"), "{stderr}");
}

/// `--run`: the network kept running after its boot; a slave that loses
/// power is lost (E), booted again when it is back and started, one line
/// each; the end is all operational: exit status 0.
#[test]
fn run_keeps_the_network_and_boots_a_returning_slave_again() {
    let (code, stdout, stderr) = run_matrix("left:power-loss=1s+300ms", "2s", &[]);
    assert_eq!(code, 0, "{stdout}{stderr}");
    let after: Vec<&str> = stdout
        .lines()
        .skip_while(|l| !l.contains("2 of 2 slaves operational in"))
        .skip(1)
        .collect();
    let texts: Vec<&str> = after
        .iter()
        .map(|l| l.split_once(" s  ").map_or(*l, |(_, t)| t))
        .collect();
    assert_eq!(
        texts,
        [
            "left (node 2): lost: E: no heartbeat came from the node",
            "left (node 2): booting again",
            "left (node 2): booted",
            "left (node 2): started",
            "tests/networks/boot/matrix.yml: 2 of 2 slaves operational after 2.000 s of running (simulated time)",
        ],
        "{stdout}"
    );
    assert!(stderr.contains("running the network for 2.0 s"), "{stderr}");

    let (code, stdout, _) = run_matrix("left:power-loss=1s+300ms", "2s", &["--format", "json"]);
    assert_eq!(code, 0, "{stdout}");
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("one JSON object");
    let events: Vec<&str> = v["events"]
        .as_array()
        .expect("events")
        .iter()
        .map(|e| e["event"].as_str().unwrap())
        .collect();
    assert_eq!(events, ["lost", "rebooting", "booted", "started"]);
    assert_eq!(v["slaves"][0]["boots"], 2);
    assert_eq!(v["ran_seconds"], 2.0);

    // The mandatory slave boots after the boot time (1 s): the network's
    // boot failed (B); booted when it comes, it is not started: exit 1.
    let (code, stdout, _) = run_matrix("left:late-boot=1500ms", "3s", &[]);
    assert_eq!(code, 1, "{stdout}");
    assert!(
        stdout.contains("left (node 2): booting again\n")
            && stdout.ends_with(
                "tests/networks/boot/matrix.yml: the network did not boot: mandatory slaves not up: \
                 left (node 2) booted\n"
            ),
        "{stdout}"
    );

    // With --simulate --run needs a time; --duration needs --run.
    let bus = "tests/networks/boot/matrix.yml";
    assert_eq!(simulate(&["--run", bus]).0, 2);
    assert_eq!(simulate(&["--duration", "1s", bus]).0, 2);
}

/// The blocks of docs/network.md's `## net boot` marked `<!-- output:
/// NAME -->` are the command on their first line (`$ eds2rust ...`) and
/// its real output; `UPDATE_DOCS=1` rewrites them instead.
#[test]
fn the_docs_show_the_real_output() {
    let path = root().join("docs/network.md");
    let mut doc = std::fs::read_to_string(&path).expect("docs/network.md");
    for name in ["net-boot-simulate", "net-boot-fault", "net-boot-run"] {
        let marker = format!("<!-- output: {name} -->\n```text\n");
        let start = doc
            .find(&marker)
            .unwrap_or_else(|| panic!("no {marker:?} in docs/network.md"))
            + marker.len();
        let end = start + doc[start..].find("```\n").expect("the block's end");
        let block = &doc[start..end];
        let command = block
            .lines()
            .next()
            .and_then(|l| l.strip_prefix("$ eds2rust "))
            .unwrap_or_else(|| panic!("block {name} does not start with `$ eds2rust `"));
        let args: Vec<&str> = command.split_whitespace().collect();
        let (_, stdout, stderr) = run(&args);
        // Only `--run`'s status line goes to stderr.
        assert!(
            stderr.lines().all(|l| l.starts_with("net boot: running")),
            "{stderr}"
        );
        let real = format!("$ eds2rust {command}\n{stdout}");
        if std::env::var_os("UPDATE_DOCS").is_some() {
            doc = format!("{}{real}{}", &doc[..start], &doc[end..]);
            continue;
        }
        assert_eq!(
            block, real,
            "docs/network.md block {name} does not show the real output; run with \
             UPDATE_DOCS=1 and review"
        );
    }
    if std::env::var_os("UPDATE_DOCS").is_some() {
        std::fs::write(&path, doc).unwrap();
    }
}
