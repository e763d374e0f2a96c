//! No input makes the reader panic: thousands of seeded random mutations of the
//! real corpus files (byte flips, inserts, deletes, line deletions,
//! duplications, swaps, truncation, hostile tokens) are read in lenient and
//! strict mode, and their diagnostics are rendered.

use std::path::PathBuf;

use eds2rust::eds::{Options, read_bytes};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

const TOKENS: &[&[u8]] = &[
    b"[",
    b"]",
    b"=",
    b";",
    b"#",
    b"$NODEID",
    b"$NODEID+",
    b"0x",
    b"\0",
    b"\r",
    b"\n",
    b"99999999999999999999999999",
    b"-",
    b"sub",
    b"CompactSubObj=255\n",
    b"SubNumber=0\n",
    b"DataType=0x0008\n",
    b"ObjectType=0x9\n",
    b"\xC3",
    b"\xFF\xFE",
];

#[derive(Debug, Clone)]
enum Mutation {
    Flip(usize, u8),
    Insert(usize, usize),
    Delete(usize, usize),
    DeleteLine(usize),
    DuplicateLine(usize),
    SwapLines(usize, usize),
    Truncate(usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(a, b)| Mutation::Flip(a, b)),
        (any::<usize>(), 0..TOKENS.len()).prop_map(|(a, t)| Mutation::Insert(a, t)),
        (any::<usize>(), 1usize..64).prop_map(|(a, n)| Mutation::Delete(a, n)),
        any::<usize>().prop_map(Mutation::DeleteLine),
        any::<usize>().prop_map(Mutation::DuplicateLine),
        (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Mutation::SwapLines(a, b)),
        any::<usize>().prop_map(Mutation::Truncate),
    ]
}

fn apply(bytes: &mut Vec<u8>, m: &Mutation) {
    let len = bytes.len().max(1);
    let lines =
        |b: &Vec<u8>| -> Vec<Vec<u8>> { b.split(|&c| c == b'\n').map(<[u8]>::to_vec).collect() };
    match *m {
        Mutation::Flip(a, v) if !bytes.is_empty() => bytes[a % len] = v,
        Mutation::Insert(a, t) => {
            let at = a % (bytes.len() + 1);
            bytes.splice(at..at, TOKENS[t].iter().copied());
        }
        Mutation::Delete(a, n) if !bytes.is_empty() => {
            let at = a % len;
            let end = (at + n).min(bytes.len());
            bytes.drain(at..end);
        }
        Mutation::DeleteLine(a) | Mutation::DuplicateLine(a) | Mutation::SwapLines(a, _) => {
            let mut ls = lines(bytes);
            let i = a % ls.len();
            match *m {
                Mutation::DeleteLine(_) => {
                    ls.remove(i);
                }
                Mutation::DuplicateLine(_) => {
                    let l = ls[i].clone();
                    ls.insert(i, l);
                }
                Mutation::SwapLines(_, b) => {
                    let j = b % ls.len();
                    ls.swap(i, j);
                }
                _ => unreachable!(),
            }
            *bytes = ls.join(&b'\n');
        }
        Mutation::Truncate(a) => bytes.truncate(a % len),
        _ => {}
    }
}

#[test]
fn mutated_corpus_never_panics() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/eds-corpus/files");
    if !dir.is_dir() {
        // A direct write: the harness captures eprintln! of passing tests, and this must be seen.
        use std::io::Write;
        let _ = writeln!(
            std::io::stderr(),
            "NOT RUN: no-panic mutation test: ../shared/eds-corpus is not beside this checkout"
        );
        return;
    }
    let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(&dir)
        .expect("corpus")
        .map(|e| e.expect("entry").path())
        .map(|p| {
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read(&p).expect("read"),
            )
        })
        .collect();
    files.sort();
    // Large files are cut to their first 24 KiB so that the cases stay fast in debug builds.
    for (_, bytes) in &mut files {
        bytes.truncate(24 * 1024);
    }
    let config = Config {
        cases: 4096,
        failure_persistence: None,
        ..Config::default()
    };
    let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &[0x30; 32]);
    let mut runner = TestRunner::new_with_rng(config, rng);
    let strategy = (0..files.len(), proptest::collection::vec(mutation(), 1..8));
    let result = runner.run(&strategy, |(file, mutations)| {
        let (name, original) = &files[file];
        let mut bytes = original.clone();
        for m in &mutations {
            apply(&mut bytes, m);
        }
        for strict in [false, true] {
            let loaded = read_bytes(
                name,
                &bytes,
                &Options {
                    strict,
                    ..Options::default()
                },
            );
            let rendered = loaded.diagnostics.render();
            prop_assert!(loaded.diagnostics.is_empty() || !rendered.is_empty());
            for d in loaded.diagnostics.iter() {
                prop_assert_eq!(&d.file, name);
            }
        }
        Ok(())
    });
    if let Err(e) = result {
        panic!("{e}");
    }
}
