//! The LINAK TECHLINE manual's start-up trace (p. 28, node 32), in the
//! manual's own order, decodes with the seed table to what the manual says
//! each frame is.

mod common;

use common::{decode, field, frames, seed, transfers};
use eds2rust_decode::Decoder;

/// The frames of the manual's table, as candump compact lines.
const TRACE: &str = "\
701#05
720#00
620#23161001C8000100
5A0#6016100100000000
000#0120
1A0#00000081010000C0
220#03FBFBFBFBFB0000
1A0#00000081000000C0
220#01FBFBFBFBFB0000
1A0#1A000688003100C0
1A0#F701008200000000C0
1A0#F7010082000000C0
220#02FBFBFBFBFB0000
1A0#60000690003200C0
1A0#00000081000000C0
";

#[test]
fn startup_trace_decodes_to_the_manuals_values() {
    let mut decoder = Decoder::new();
    decoder.add_node(32, seed("linak_techline"));
    let records = decode(&mut decoder, TRACE);
    // Line 11 is a deliberately broken copy (9 data bytes): a diagnostic,
    // and decoding goes on.
    let diagnostics: Vec<_> = records
        .iter()
        .filter(|r| r["event"] == "diagnostic")
        .collect();
    assert_eq!(diagnostics.len(), 1, "{records:#?}");
    assert_eq!(diagnostics[0]["line"], 11);
    let f = frames(&records);
    assert_eq!(f.len(), 14);

    // "Master-Takt": the master's heartbeat (node 1, operational).
    assert_eq!(f[0]["protocol"], "heartbeat");
    assert_eq!(
        (f[0]["node"].as_u64(), f[0]["state"].as_str()),
        (Some(1), Some("operational"))
    );
    // "Booten des Aktuators": boot-up of node 32.
    assert_eq!(f[1]["protocol"], "heartbeat");
    assert_eq!(f[1]["text"], "boot-up node 32");
    // The SDO write of 0x1016 sub 1 and the actuator's answer.
    assert_eq!(
        (f[2]["protocol"].as_str(), f[2]["role"].as_str()),
        (Some("sdo"), Some("client"))
    );
    assert_eq!(
        (f[2]["index"].as_u64(), f[2]["subindex"].as_u64()),
        (Some(0x1016), Some(1))
    );
    assert_eq!(f[3]["role"], "server");
    assert_eq!(f[3]["command"], "download-response");
    let t = transfers(&records);
    assert_eq!(t.len(), 1);
    assert_eq!(t[0]["direction"], "download");
    assert_eq!(t[0]["value"], 0x0001_00C8, "node 1, 200 ms");
    assert_eq!(t[0]["result"], "ok");
    assert!(
        t[0]["name"]
            .as_str()
            .unwrap()
            .starts_with("Consumer heartbeat time"),
        "{}",
        t[0]
    );
    // NMT start of node 32.
    assert_eq!(f[4]["protocol"], "nmt");
    assert_eq!(
        (f[4]["command"].as_str(), f[4]["target"].as_u64()),
        (Some("start"), Some(32))
    );

    // TPDO1 before the first Stop: "Stopp-Befehl erforderlich" (error 1, power-up lock).
    let tpdo = |k: usize| {
        assert_eq!(
            (f[k]["protocol"].as_str(), f[k]["pdo"].as_str()),
            (Some("pdo"), Some("tpdo1")),
            "{}",
            f[k]
        );
        f[k]
    };
    let first = tpdo(5);
    assert_eq!(field(first, "Feedback.Error code")["raw"], 1);
    assert_eq!(
        field(first, "Feedback.Error code")["value"],
        "power up lock"
    );
    assert_eq!(field(first, "Feedback.Position")["value"], 0.0);
    // RPDO1 "Stopp-Befehl", then end stop inwards at 0 mm.
    assert_eq!(f[6]["pdo"], "rpdo1");
    assert_eq!(field(f[6], "Command.Position")["value"], "stop");
    assert_eq!(field(tpdo(7), "Feedback.Position")["value"], 0.0);
    assert_eq!(field(f[7], "Feedback.Error code")["raw"], 0);
    // "Ausfahren", then running out at 2.6 mm, 1.5 A, 4.9 mm/s.
    assert_eq!(field(f[8], "Command.Position")["value"], "run out");
    let out = tpdo(9);
    assert_eq!(field(out, "Feedback.Position")["value"], 2.6);
    assert_eq!(field(out, "Feedback.Position")["unit"], "mm");
    assert_eq!(field(out, "Feedback.Current")["value"], 1.5);
    assert_eq!(field(out, "Feedback.Speed")["value"], 4.9);
    assert!(
        field(out, "Feedback.Status flags")["text"]
            .as_str()
            .unwrap()
            .contains("running out")
    );
    // End stop outwards at 50.3 mm.
    let end_out = tpdo(10);
    assert_eq!(field(end_out, "Feedback.Position")["value"], 50.3);
    assert!(
        field(end_out, "Feedback.Status flags")["text"]
            .as_str()
            .unwrap()
            .contains("end stop out"),
        "{end_out}"
    );
    // "Einfahren", running in at 9.6 mm, then end stop inwards at 0 mm.
    assert_eq!(field(f[11], "Command.Position")["value"], "run in");
    assert_eq!(field(tpdo(12), "Feedback.Position")["value"], 9.6);
    assert!(
        field(f[12], "Feedback.Status flags")["text"]
            .as_str()
            .unwrap()
            .contains("running in")
    );
    assert_eq!(field(tpdo(13), "Feedback.Position")["value"], 0.0);
    assert!(
        field(f[13], "Feedback.Status flags")["text"]
            .as_str()
            .unwrap()
            .contains("end stop in")
    );
}
