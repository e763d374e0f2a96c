//! The Python oracles (python-canopen, and lely's dcfgen from dcf-tools): a
//! virtual environment that the tests create by themselves on first use,
//! under the target directory, with the pinned packages of
//! `tests/python/requirements.txt`.
//!
//! Creation is guarded by a file lock, so parallel test processes share one
//! environment. Any failure is an error with the reason: tests that need the
//! oracle fail, they never skip.

use std::fs::{self, File};
use std::path::{Path, PathBuf};
use std::process::Command;

use crate::{target_dir, workspace_root};

/// The directory of the oracle's scripts (`tests/python`).
pub fn scripts_dir() -> PathBuf {
    workspace_root().join("tests").join("python")
}

/// Path of the environment's Python interpreter, creating the environment when
/// it is missing or its requirements changed.
pub fn python() -> Result<PathBuf, String> {
    let requirements_path = scripts_dir().join("requirements.txt");
    let requirements = fs::read_to_string(&requirements_path)
        .map_err(|e| format!("cannot read {}: {e}", requirements_path.display()))?;
    let target = target_dir();
    fs::create_dir_all(&target).map_err(|e| format!("cannot create {}: {e}", target.display()))?;
    let venv = target.join("pyoracle");
    let lock_path = target.join("pyoracle.lock");
    let lock = File::create(&lock_path)
        .map_err(|e| format!("cannot create {}: {e}", lock_path.display()))?;
    lock.lock()
        .map_err(|e| format!("cannot lock {}: {e}", lock_path.display()))?;
    let stamp = venv.join("requirements.installed");
    let interpreter = venv.join("bin").join("python");
    if fs::read_to_string(&stamp).ok().as_deref() == Some(requirements.as_str())
        && interpreter.exists()
    {
        return Ok(interpreter);
    }
    let _ = fs::remove_dir_all(&venv);
    let system_python = std::env::var("PYTHON").unwrap_or_else(|_| "python3".to_string());
    run(
        Command::new(&system_python).args(["-m", "venv"]).arg(&venv),
        "create the python-canopen venv",
    )?;
    run(
        Command::new(&interpreter)
            .args([
                "-m",
                "pip",
                "install",
                "--quiet",
                "--disable-pip-version-check",
                "-r",
            ])
            .arg(&requirements_path),
        "install the pinned python-canopen packages",
    )?;
    fs::write(&stamp, &requirements)
        .map_err(|e| format!("cannot write {}: {e}", stamp.display()))?;
    Ok(interpreter)
}

/// Path of lely's `dcfgen` in the oracle's environment (dcf-tools, pinned
/// in `tests/python/requirements.txt`), creating the environment first.
pub fn dcfgen() -> Result<PathBuf, String> {
    let python = python()?;
    let dcfgen = python.with_file_name("dcfgen");
    if dcfgen.exists() {
        Ok(dcfgen)
    } else {
        Err(format!(
            "{} is missing: dcf-tools did not install its command",
            dcfgen.display()
        ))
    }
}

fn run(command: &mut Command, what: &str) -> Result<(), String> {
    let output = command
        .output()
        .map_err(|e| format!("cannot {what}: {e} (is python3 with venv installed?)"))?;
    if output.status.success() {
        Ok(())
    } else {
        Err(format!(
            "cannot {what}: {}\n{}{}",
            output.status,
            String::from_utf8_lossy(&output.stdout),
            String::from_utf8_lossy(&output.stderr)
        ))
    }
}

/// Runs a script of `tests/python` with the oracle's interpreter and returns its stdout.
pub fn run_script(script: &str, args: &[&Path], extra: &[&str]) -> Result<String, String> {
    let python = python()?;
    let output = Command::new(python)
        .arg(scripts_dir().join(script))
        .args(extra)
        .args(args)
        .output()
        .map_err(|e| format!("cannot run {script}: {e}"))?;
    if !output.status.success() {
        return Err(format!(
            "{script} failed: {}\n{}",
            output.status,
            String::from_utf8_lossy(&output.stderr)
        ));
    }
    String::from_utf8(output.stdout).map_err(|e| format!("{script} printed non-UTF-8: {e}"))
}

/// The fields of an entry that the python-canopen comparisons check, in the
/// schema of `eds2rust dump --format json` (and of `od_dump.py`).
pub const COMPARED_FIELDS: &[&str] = &[
    "data_type",
    "access",
    "pdo_mappable",
    "default",
    "low_limit",
    "high_limit",
    "parameter_value",
];

/// Two values of one field equal as JSON, numbers compared by value (REAL32
/// at f32 precision).
pub fn same_value(
    ours: &serde_json::Value,
    theirs: &serde_json::Value,
    data_type: eds2rust::ir::DataType,
) -> bool {
    use serde_json::Value;
    match (ours, theirs) {
        (Value::Number(a), Value::Number(b)) => {
            if let (Some(a), Some(b)) = (a.as_i64(), b.as_i64()) {
                return a == b;
            }
            if let (Some(a), Some(b)) = (a.as_u64(), b.as_u64()) {
                return a == b;
            }
            match (a.as_f64(), b.as_f64()) {
                (Some(a), Some(b)) if data_type == eds2rust::ir::DataType::Real32 => {
                    (a as f32) == (b as f32)
                }
                (Some(a), Some(b)) => a == b,
                _ => false,
            }
        }
        _ => ours == theirs,
    }
}

/// Runs a per-file oracle (`od_dump.py`, `od_export_check.py`: `--node-id
/// N FILE...`, one JSON line per file) on `paths`; one result per path, in
/// order (checked by its `file`).
pub fn run_per_file(script: &str, paths: &[&Path], node_id: u8) -> Vec<serde_json::Value> {
    let node = node_id.to_string();
    let out = run_script(script, paths, &["--node-id", &node])
        .unwrap_or_else(|e| panic!("the python-canopen oracle could not run: {e}"));
    let results: Vec<serde_json::Value> = out
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            serde_json::from_str(l).unwrap_or_else(|e| panic!("{script} prints JSON lines: {e}"))
        })
        .collect();
    assert_eq!(results.len(), paths.len(), "one result per file");
    for (path, result) in paths.iter().zip(&results) {
        assert_eq!(
            result["file"].as_str(),
            path.to_str(),
            "results come in file order"
        );
    }
    results
}

/// How python-canopen's entries compare with ours, entry by entry.
#[derive(Default)]
pub struct Agreement {
    /// Entries python-canopen has.
    pub compared: usize,
    /// Entries equal on every compared field.
    pub agreed: usize,
    /// Entries that differ only as a rule explains, by the first rule.
    pub by_rule: std::collections::BTreeMap<&'static str, usize>,
    /// `NAME 0xINDEX sub SUB: ...` of every other entry.
    pub unexplained: Vec<String>,
}

impl Agreement {
    /// Compares python-canopen's `entries` (in the dump's JSON schema) of
    /// the file `name` with ours: `ours` is `eds2rust dump --format json`
    /// of `device`. Each entry agrees on every [`COMPARED_FIELDS`] field
    /// ([`same_value`]), or differs as `explain(index, entry, field, ours,
    /// theirs)` names a rule for every differing field, or is unexplained.
    /// python-canopen's dummy objects (0x0001..=0x0007) count as the rule
    /// `dummy-objects`.
    pub fn compare(
        &mut self,
        name: &str,
        device: &eds2rust::ir::Device,
        ours: &serde_json::Value,
        entries: &serde_json::Value,
        explain: impl Fn(
            u16,
            &eds2rust::ir::Entry,
            &str,
            &serde_json::Value,
            &serde_json::Value,
        ) -> Option<&'static str>,
    ) {
        let key = |e: &serde_json::Value| (e["index"].as_u64(), e["subindex"].as_u64());
        let ours_by_key: std::collections::BTreeMap<_, &serde_json::Value> = ours["entries"]
            .as_array()
            .into_iter()
            .flatten()
            .map(|e| (key(e), e))
            .collect();
        for theirs in entries.as_array().into_iter().flatten() {
            let (Some(index), Some(sub)) = key(theirs) else {
                panic!("{name}: python entry without index: {theirs}");
            };
            let where_ = format!("{name} 0x{index:04X} sub {sub}");
            self.compared += 1;
            if (1..=7).contains(&index)
                && theirs["name"]
                    .as_str()
                    .is_some_and(|n| n.starts_with("Dummy"))
            {
                *self.by_rule.entry("dummy-objects").or_default() += 1;
                continue;
            }
            let entry = u16::try_from(index)
                .ok()
                .and_then(|i| device.objects.get(&i))
                .and_then(|o| o.entries.get(&u8::try_from(sub).ok()?));
            let (Some(our), Some(entry)) = (ours_by_key.get(&(Some(index), Some(sub))), entry)
            else {
                self.unexplained.push(format!(
                    "{where_}: python-canopen has `{}`, eds2rust has no such entry",
                    theirs["name"]
                ));
                continue;
            };
            let mut rules = Vec::new();
            let mut mismatch = Vec::new();
            for &field in COMPARED_FIELDS {
                let (a, b) = (&our[field], &theirs[field]);
                if same_value(a, b, entry.data_type) {
                    continue;
                }
                match explain(index as u16, entry, field, a, b) {
                    Some(rule) => rules.push(rule),
                    None => mismatch.push(format!("{field}: eds2rust {a}, python-canopen {b}")),
                }
            }
            if !mismatch.is_empty() {
                self.unexplained
                    .push(format!("{where_}: {}", mismatch.join("; ")));
            } else if let Some(rule) = rules.first() {
                *self.by_rule.entry(rule).or_default() += 1;
            } else {
                self.agreed += 1;
            }
        }
    }
}
