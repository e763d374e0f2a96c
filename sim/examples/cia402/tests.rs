//! The example's tests: every corpus drive with both masters, one drive
//! there and back, files that are no drive, an overlay, the command line.

use super::*;
use std::path::Path;

fn corpus(name: &str) -> Option<PathBuf> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/eds-corpus/files")
        .join(name);
    if path.exists() {
        Some(path)
    } else {
        use std::io::Write as _;
        let _ = writeln!(
            std::io::stderr(),
            "NOT RUN: cia402 example on {name}: ../shared/eds-corpus is not beside this checkout"
        );
        None
    }
}

fn table_has_position(path: &Path) -> bool {
    file::load(path).is_ok_and(|t| t.has(object::POSITION_ACTUAL_VALUE))
}

/// The lines both masters must print alike: transitions and the
/// positions reached (without the drive time, which varies), up to the
/// quick stop. After it a drive whose option code ends in Switch on
/// disabled gets there after its deceleration: whether the last
/// statusword shows Quick stop active or already Switch on disabled
/// is timing.
fn outcome(text: &str) -> Vec<String> {
    text.lines()
        .take_while(|l| *l != "quick stop")
        .filter(|l| l.starts_with("state:") || l.starts_with("target reached at"))
        .map(|l| l.split(" (after").next().unwrap_or(l).to_string())
        .collect()
}

/// Every CiA 402 drive of the corpus moves there and back and
/// quick-stops with both masters, printing the same transitions and
/// positions, or the example says which object the file lacks.
#[test]
fn every_corpus_drive_moves_with_both_masters_or_names_what_it_lacks() {
    let Some(dir) = corpus("") else {
        return;
    };
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("the corpus")
        .map(|e| e.expect("an entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "eds" || e == "dcf"))
        .collect();
    files.sort();
    let (mut reached, mut lacking, mut refused) = (Vec::new(), Vec::new(), Vec::new());
    for path in files {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let table = match file::load(&path) {
            Ok(table) => table,
            Err(e) => {
                refused.push((name, e.to_string()));
                continue;
            }
        };
        if !table.cia402 {
            continue;
        }
        let mut outcomes = Vec::new();
        for asynchronous in [false, true] {
            let mut out = Vec::new();
            let mut a = args(path.clone());
            a.time_scale = 50.0;
            a.asynchronous = asynchronous;
            let text = |out: &[u8]| String::from_utf8_lossy(out).into_owned();
            match run(&a, &mut out) {
                Ok(summary) => {
                    let text = text(&out);
                    // A drive without 0x6064 reaches its targets
                    // without a position to read back.
                    if table_has_position(&a.file) {
                        assert_eq!(summary.reached, summary.targets, "{name}: {text}");
                    }
                    assert_eq!(text.matches("target reached").count(), 2, "{name}: {text}");
                    assert!(text.contains("-> Operation enabled"), "{name}: {text}");
                    assert!(
                        matches!(
                            summary.state,
                            Some(State::QuickStopActive | State::SwitchOnDisabled)
                        ),
                        "{name}: {text}"
                    );
                    outcomes.push(Ok(outcome(&text)));
                }
                Err(e) => {
                    assert!(
                        e.0.contains("which this device does not have"),
                        "{name} (async: {asynchronous}): {e}\n{}",
                        text(&out)
                    );
                    outcomes.push(Err(e.0));
                }
            }
        }
        assert_eq!(outcomes[0], outcomes[1], "{name}: blocking vs tokio");
        match outcomes.swap_remove(0) {
            Ok(_) => reached.push(name),
            Err(e) => lacking.push(e),
        }
    }
    use std::io::Write as _;
    let _ = writeln!(
        std::io::stderr(),
        "cia402 example, blocking and tokio master alike: {} corpus drives reached both targets \
         and quick-stopped: {reached:?}; {} lack an object: {lacking:?}",
        reached.len(),
        lacking.len()
    );
    assert!(reached.len() >= 20, "{reached:?}");
    let refused_names: Vec<&str> = refused.iter().map(|(name, _)| name.as_str()).collect();
    let expected: Vec<&str> = NOT_LOADING.iter().map(|(name, _)| *name).collect();
    assert_eq!(
        refused_names, expected,
        "corpus files that do not load: {refused:#?}"
    );
    for ((name, error), (_, why)) in refused.iter().zip(NOT_LOADING) {
        assert!(
            error.contains(why),
            "{name}: expected {why:?}, got: {error}"
        );
    }
}

/// The corpus files the simulator's loader refuses (in file-name order),
/// each with a part of the error that says why.
const NOT_LOADING: &[(&str, &str)] = &[];

fn args(file: PathBuf) -> Args {
    Args {
        file,
        overlays: Vec::new(),
        node: None,
        time_scale: 20.0,
        trace: false,
        asynchronous: false,
    }
}

#[test]
fn moves_a_corpus_drive_there_and_back() {
    let Some(file) = corpus("ros2-canopen_cia402-slave.eds") else {
        return;
    };
    let mut out = Vec::new();
    let summary = run(&args(file), &mut out);
    let text = String::from_utf8_lossy(&out);
    let summary = summary.unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert_eq!(summary.reached, summary.targets, "{text}");
    assert!(
        text.contains("state: Switched on -> Operation enabled"),
        "{text}"
    );
    assert!(
        text.contains(&format!("target reached at {}", summary.targets[0])),
        "{text}"
    );
    assert!(matches!(
        summary.state,
        Some(State::QuickStopActive | State::SwitchOnDisabled)
    ));
}

#[test]
fn a_file_that_is_no_drive_says_so() {
    let Some(file) = corpus("cia401_sample.eds") else {
        return;
    };
    let e = run(&args(file), &mut Vec::new()).expect_err("refused");
    assert!(
        e.0.contains("not a CiA 402 drive: no 0x6040 Controlword"),
        "{e}"
    );
    let Some(file) = corpus("stm32_cia418-reference.eds") else {
        return;
    };
    let e = run(&args(file), &mut Vec::new()).expect_err("refused");
    assert!(
        e.0.contains(
            "not a CiA 402 drive: 0x1000 Device type 0x00000000 names profile 0, \
             and 0x6040/0x6041 are not UNSIGNED16 variables"
        ),
        "{e}"
    );
}

/// An overlay that deletes 0x607A: the runtime's check refuses profile
/// position before any frame, naming the object.
#[test]
fn an_overlay_applies_and_a_missing_object_is_named() {
    let Some(file) = corpus("cia402_sample.eds") else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("eds2rust-cia402-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let overlay = dir.join("no-target.yaml");
    std::fs::write(&overlay, "format: 1\ndelete:\n  - { index: 0x607A }\n").unwrap();
    let mut a = args(file);
    a.overlays = vec![overlay];
    for asynchronous in [false, true] {
        a.asynchronous = asynchronous;
        let e = run(&a, &mut Vec::new()).expect_err("refused");
        assert!(
            e.0.ends_with(
                "profile position needs 0x607A Target position, which this device does not have"
            ),
            "{e}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_command_line() {
    let a = parse(["f.eds", "--node", "9", "--async", "--overlay", "o.yaml"].map(String::from))
        .expect("parses");
    assert_eq!((a.node, a.asynchronous), (Some(9), true));
    assert_eq!(a.overlays, [PathBuf::from("o.yaml")]);
    assert!(parse(["f.eds", "--overlay"].map(String::from)).is_err());
    assert!(parse(["--node", "0", "f.eds"].map(String::from)).is_err());
    assert!(parse(["f.eds", "g.eds"].map(String::from)).is_err());
    assert!(parse(Vec::<String>::new()).is_err());
}
