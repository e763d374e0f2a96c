//! A trace produced by python-canopen (`eds2rust_tests::recording`: its
//! RemoteNode against the Interroll simulator, its LocalNode sending EMCY
//! and heartbeats) decodes with the seed table to what python-canopen says
//! it sent and received: every SDO transfer (expedited, segmented, block,
//! both ways) with its bytes, every PDO with the raw value of every mapped
//! variable, the EMCYs and the heartbeats.

use std::sync::Arc;

use eds2rust_decode::{Decoder, Record, render};
use eds2rust_sim::models;
use eds2rust_tests::recording::{self, Session};
use serde_json::Value as Json;

fn session() -> Session {
    recording::python_session_with(models::interroll_ec5000bi::simulator)
        .unwrap_or_else(|e| panic!("{e}"))
}

fn decode(s: &Session) -> Vec<Json> {
    let root = eds2rust_tests::workspace_root();
    let path = root.join(format!("eds/{}.yaml", s.device));
    let loaded = eds2rust::input::read_device(&path, &eds2rust::input::Options::default());
    let mut decoder = Decoder::new();
    decoder.add_node(s.node, Arc::new(loaded.device.expect("seed device")));
    let mut out = Vec::new();
    let summary = eds2rust_decode::decode_trace(&mut decoder, s.trace.as_bytes(), |r: &Record| {
        out.push(render::json(r));
        Ok(())
    })
    .expect("decode");
    assert_eq!(summary.bad_lines, 0);
    out
}

fn hex(data: &[u8]) -> String {
    data.iter().map(|b| format!("{b:02X}")).collect()
}

#[test]
fn python_canopen_session_decodes_to_what_it_sent() {
    let s = session();
    let records = decode(&s);
    let frames: Vec<&Json> = records
        .iter()
        .filter(|r| r.get("event").is_none())
        .collect();
    for f in &frames {
        assert_ne!(f["protocol"], "unknown", "{f}");
    }

    // SDO: one transfer record per transfer python-canopen made, in order,
    // with the same bytes, direction and method.
    let transfers: Vec<&Json> = records
        .iter()
        .filter(|r| r["event"] == "sdo-transfer")
        .collect();
    assert_eq!(transfers.len(), s.sdo.len(), "{transfers:#?}");
    for (t, op) in transfers.iter().zip(&s.sdo) {
        let what = format!("0x{:04X}.{} {t}", op.index, op.subindex);
        assert_eq!(
            (t["index"].as_u64(), t["subindex"].as_u64()),
            (Some(op.index.into()), Some(op.subindex.into())),
            "{what}"
        );
        assert_eq!(
            t["direction"],
            if op.upload { "upload" } else { "download" },
            "{what}"
        );
        let method = match (op.block, op.segmented) {
            (true, _) => "block",
            (false, true) => "segmented",
            (false, false) => "expedited",
        };
        assert_eq!(t["method"], method, "{what}");
        match op.abort {
            Some(code) => assert_eq!(t["result"], format!("abort {code:#010x}"), "{what}"),
            None => {
                assert_eq!(t["result"], "ok", "{what}");
                assert_eq!(t["data"], hex(&op.data), "{what}");
            }
        }
        assert_eq!(t["node"], s.node);
    }
    assert!(
        s.sdo.iter().any(|o| o.block && o.upload) && s.sdo.iter().any(|o| o.block && !o.upload)
    );

    // PDOs: every frame python-canopen decoded, with every variable's raw value.
    let pdos: Vec<&&Json> = frames
        .iter()
        .filter(|f| f["protocol"] == "pdo" && f["node"] == s.node)
        .collect();
    let tpdos: Vec<&&Json> = pdos
        .iter()
        .copied()
        .filter(|f| f["pdo"].as_str().unwrap().starts_with("tpdo"))
        .collect();
    assert_eq!(tpdos.len(), s.pdos.len(), "{tpdos:#?}");
    for (f, seen) in tpdos.iter().zip(&s.pdos) {
        assert_eq!(f["id"], seen.cob_id, "{f}");
        assert_eq!(f["data"], hex(&seen.data), "{f}");
        assert_eq!(f["pdo"], format!("tpdo{}", seen.tpdo), "{f}");
        let fields = f["fields"].as_array().expect("fields");
        assert_eq!(fields.len(), seen.fields.len(), "{f}");
        for (ours, (name, index, sub, raw)) in fields.iter().zip(&seen.fields) {
            assert_eq!(
                (ours["index"].as_u64(), ours["subindex"].as_u64()),
                (Some(u64::from(*index)), Some(u64::from(*sub))),
                "{name}: {f}"
            );
            assert_eq!(ours["raw"].as_i64(), Some(*raw), "{name}: {f}");
            assert!(
                ours["name"].as_str().unwrap().contains(name.as_str()),
                "{name} vs {ours}"
            );
        }
    }

    // EMCY: code, error register and manufacturer bytes of each one sent.
    let emcy: Vec<&&Json> = frames.iter().filter(|f| f["protocol"] == "emcy").collect();
    assert_eq!(emcy.len(), s.emcy.len());
    for (f, sent) in emcy.iter().zip(&s.emcy) {
        assert_eq!(f["node"], sent.node);
        assert_eq!(f["code"], sent.code);
        assert_eq!(f["register"], sent.register);
        let mut m = sent.data.clone();
        m.resize(5, 0);
        assert_eq!(f["manufacturer"], hex(&m), "{f}");
    }

    // Heartbeats and boot-ups: node and state byte, in order.
    let beats: Vec<(u64, &str)> = frames
        .iter()
        .filter(|f| f["protocol"] == "heartbeat")
        .map(|f| (f["node"].as_u64().unwrap(), f["state"].as_str().unwrap()))
        .collect();
    let expected: Vec<(u64, String)> = s
        .heartbeats
        .iter()
        .map(|&(n, state)| {
            let name = match state {
                0x00 => "boot-up",
                0x04 => "stopped",
                0x05 => "operational",
                0x7F => "pre-operational",
                other => panic!("state {other:#04X}"),
            };
            (u64::from(n), name.to_string())
        })
        .collect();
    let mut beats_sorted = beats.clone();
    let mut expected_sorted: Vec<(u64, &str)> =
        expected.iter().map(|(n, s)| (*n, s.as_str())).collect();
    beats_sorted.sort();
    expected_sorted.sort();
    assert_eq!(beats_sorted, expected_sorted);
    // NMT and SYNC are there too.
    assert!(
        frames
            .iter()
            .any(|f| f["protocol"] == "nmt" && f["command"] == "start")
    );
    assert_eq!(frames.iter().filter(|f| f["protocol"] == "sync").count(), 2);
}
