//! One frame of every CiA 301 / CiA 305 protocol, as the decoder names it:
//! NMT, SYNC, TIME, EMCY (with the device's error table), heartbeat and
//! boot-up, node guarding, LSS, PDOs without a file, frames nothing
//! explains, extended and remote frames.

mod common;

use common::{decode, frames, seed};
use eds2rust_decode::Decoder;

#[test]
fn every_protocol_by_name() {
    let mut decoder = Decoder::new();
    decoder.add_node(32, seed("linak_techline"));
    let trace = "\
000#8100
000#0205
080#
080#07
100#10270000F016
0A0#2132000102030405
0A0#0000000000000000
085#1081110000000000
720#7F
705#04
705#R1
705#84
7E5#0400000000000000
7E5#1105000000000000
7E4#1100000000000000
185#112233
7FF#0102
12345678#AABB
3A0#R
0A0#0102
";
    let records = decode(&mut decoder, trace);
    let f = frames(&records);
    let text = |k: usize| f[k]["text"].as_str().unwrap().to_string();
    let protocol = |k: usize| f[k]["protocol"].as_str().unwrap().to_string();

    assert_eq!(
        (
            protocol(0),
            f[0]["command"].as_str(),
            f[0]["target"].is_null()
        ),
        ("nmt".into(), Some("reset node"), true)
    );
    assert_eq!(text(0), "NMT reset node → all nodes");
    assert_eq!(f[1]["target"], 5);
    assert_eq!(
        (protocol(2), f[2]["counter"].is_null()),
        ("sync".into(), true)
    );
    assert_eq!(f[3]["counter"], 7);
    // TIME: 10000 ms after midnight of day 0x16F0 (5872) since 1984-01-01.
    assert_eq!(protocol(4), "time");
    assert_eq!(f[4]["timestamp"], "2000-01-29T00:00:10.000Z", "{}", f[4]);
    // EMCY of node 32 with the LINAK table's text; a reset; node 5 without a file.
    assert_eq!(
        (protocol(5), f[5]["node"].as_u64(), f[5]["code"].as_u64()),
        ("emcy".into(), Some(32), Some(0x3221))
    );
    assert!(
        f[5]["error"].as_str().unwrap().contains("undervoltage"),
        "{}",
        f[5]
    );
    assert_eq!(f[5]["manufacturer"], "0102030405");
    assert_eq!(f[6]["code"], 0);
    assert!(text(6).contains("error reset"), "{}", text(6));
    assert_eq!(f[7]["code"], 0x8110);
    assert_eq!(f[7]["error"], serde_json::Value::Null);
    assert!(text(7).contains("CAN overrun"), "{}", text(7));
    assert_eq!(f[7]["manufacturer"], "0000000000");
    // Heartbeats, then node guarding (a remote request makes 705's next
    // frame a guarding reply with its toggle bit).
    assert_eq!(
        (protocol(8), f[8]["state"].as_str()),
        ("heartbeat".into(), Some("pre-operational"))
    );
    assert_eq!(f[9]["state"], "stopped");
    assert_eq!(
        (protocol(10), text(10)),
        ("guarding".into(), "node guarding request node 5".into())
    );
    assert_eq!(
        (protocol(11), f[11]["state"].as_str()),
        ("guarding".into(), Some("stopped"))
    );
    assert!(text(11).contains("toggle 1"));
    // LSS: switch state global (configuration), configure node id 5, its answer.
    assert_eq!(protocol(12), "lss");
    assert!(text(12).contains("SwitchStateGlobal"), "{}", text(12));
    assert!(text(13).contains("ConfigureNodeId(5)"), "{}", text(13));
    assert!(text(14).starts_with("LSS response"), "{}", text(14));
    // A PDO of a node without a file: its number, raw.
    assert_eq!(
        (protocol(15), f[15]["pdo"].as_str(), f[15]["node"].as_u64()),
        ("pdo".into(), Some("tpdo1"), Some(5))
    );
    assert_eq!(f[15]["fields"].as_array().map(Vec::len), Some(0));
    // Nothing explains 0x7FF or an extended identifier nobody configured.
    assert_eq!(protocol(16), "unknown");
    assert_eq!(
        (
            protocol(17),
            f[17]["extended"].as_bool(),
            f[17]["id"].as_u64()
        ),
        ("unknown".into(), Some(true), Some(0x1234_5678))
    );
    // A remote request for TPDO2 of node 32; an EMCY that is too short.
    assert_eq!(
        (protocol(18), f[18]["remote"].as_bool()),
        ("pdo".into(), Some(true))
    );
    assert!(f[18]["problem"].as_str().unwrap().contains("remote"));
    assert_eq!(protocol(19), "emcy");
    assert!(text(19).contains("invalid frame"), "{}", text(19));
}

/// Arbitrary frames on every identifier the nodes use (SDO in the middle
/// of any transfer state, PDOs of any length, remote frames, extended
/// identifiers) never make the decoder panic, and every frame gives a
/// record.
#[test]
fn arbitrary_frames_never_panic() {
    use eds2rust_runtime::{CanId, Frame};
    let mut decoder = Decoder::new();
    decoder.add_node(32, seed("linak_techline"));
    decoder.add_node(40, seed("zimmer_acs"));
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let ids = [
        0x000, 0x080, 0x0A0, 0x100, 0x1A0, 0x220, 0x2A8, 0x5A0, 0x620, 0x5A8, 0x628, 0x720, 0x7E4,
        0x7E5,
    ];
    let mut out = Vec::new();
    for i in 0..200_000 {
        let r = next();
        let len = (r % 9) as usize;
        let bytes = next().to_le_bytes();
        let frame = match r >> 60 {
            0 => Frame::remote(
                CanId::Standard(ids[(r >> 8) as usize % ids.len()]),
                len as u8,
            ),
            1 => Frame::new(
                CanId::Extended((r >> 16) as u32 & 0x1FFF_FFFF),
                &bytes[..len],
            ),
            _ => Frame::new(
                CanId::Standard(ids[(r >> 8) as usize % ids.len()]),
                &bytes[..len],
            ),
        }
        .expect("a frame");
        out.clear();
        decoder.frame(i + 1, None, &frame, &mut out);
        assert!(!out.is_empty());
        for record in &out {
            let _ = eds2rust_decode::render::text(record);
            let _ = eds2rust_decode::render::json(record);
        }
    }
}
