//! SDO transfers reassembled from hand-written frames of CiA 301: expedited,
//! segmented and block, both directions; a block segment sent again after
//! a partial acknowledgement; aborts; a trace that starts in the middle of
//! a transfer; and PDO mappings changed by the trace's own SDO writes.

mod common;

use common::{decode, field, frames, seed, transfers};
use eds2rust_decode::Decoder;

/// Node 40, no file: the transfers are still reassembled (values as hex).
fn bare() -> Decoder {
    Decoder::new()
}

#[test]
fn expedited_and_segmented_both_ways() {
    let trace = "\
628#4018100100000000
5A8#4318100178563412
628#2B17100064000000
5A8#6017100000000000
628#4008100000000000
5A8#4108100009000000
628#6000000000000000
5A8#00414353343020202000
5A8#0041435334302020
628#7000000000000000
5A8#1B36300000000000
628#2108100005000000
5A8#6008100000000000
628#054C413336000000
5A8#2000000000000000
";
    let records = decode(&mut bare(), trace);
    let t = transfers(&records);
    assert_eq!(t.len(), 4, "{records:#?}");
    assert_eq!(
        (t[0]["direction"].as_str(), t[0]["method"].as_str()),
        (Some("upload"), Some("expedited"))
    );
    assert_eq!(
        (t[0]["index"].as_u64(), t[0]["subindex"].as_u64()),
        (Some(0x1018), Some(1))
    );
    assert_eq!(t[0]["data"], "78563412");
    assert_eq!(
        (t[1]["direction"].as_str(), t[1]["data"].as_str()),
        (Some("download"), Some("6400"))
    );
    // A segmented upload of 9 bytes, one broken line (9 data bytes) in between.
    assert_eq!(
        (t[2]["method"].as_str(), t[2]["data"].as_str()),
        (Some("segmented"), Some("414353343020203630"))
    );
    assert_eq!(t[2]["result"], "ok");
    assert!(
        records
            .iter()
            .any(|r| r["event"] == "diagnostic" && r["line"] == 8)
    );
    // A segmented download of 5 bytes (one segment, 2 unused bytes: 0x0D).
    assert_eq!(
        (t[3]["direction"].as_str(), t[3]["data"].as_str()),
        (Some("download"), Some("4C41333600"))
    );
    // Every SDO frame names its side and its index.
    for f in frames(&records) {
        assert_eq!(f["protocol"], "sdo", "{f}");
        assert!(f["role"] == "client" || f["role"] == "server");
        assert!(f["index"].is_u64(), "{f}");
        assert_eq!(f["node"], 40);
    }
}

#[test]
fn block_download_with_a_segment_sent_again() {
    // 10 bytes "0123456789" to 0x2000 sub 0; the server acknowledges only
    // segment 1 of the first block, so the client sends segment 2 again as
    // segment 1 of the next block.
    let trace = "\
628#C60020000A000000
5A8#A40020007F000000
628#0130313233343536
628#8237383900000000
5A8#A2017F0000000000
628#8137383900000000
5A8#A2017F0000000000
628#D1ABCD0000000000
5A8#A100000000000000
";
    let records = decode(&mut bare(), trace);
    let t = transfers(&records);
    assert_eq!(t.len(), 1, "{records:#?}");
    assert_eq!(
        (t[0]["method"].as_str(), t[0]["direction"].as_str()),
        (Some("block"), Some("download"))
    );
    assert_eq!(t[0]["data"], "30313233343536373839");
    let f = frames(&records);
    assert_eq!(f[2]["command"], "block-segment");
    assert_eq!(f[4]["command"], "block-download-ack");
    assert_eq!(f[7]["command"], "block-download-end");
}

#[test]
fn block_upload_and_aborts() {
    let trace = "\
628#A40020007F000000
5A8#C60020000A000000
628#A300000000000000
5A8#0130313233343536
5A8#8237383900000000
628#A2027F0000000000
5A8#D1ABCD0000000000
628#A100000000000000
628#4000300000000000
5A8#8000300000000206
628#2300300001000000
5A8#8000300002000106
";
    let records = decode(&mut bare(), trace);
    let t = transfers(&records);
    assert_eq!(t.len(), 3, "{records:#?}");
    assert_eq!(
        (t[0]["method"].as_str(), t[0]["direction"].as_str()),
        (Some("block"), Some("upload"))
    );
    assert_eq!(t[0]["data"], "30313233343536373839");
    assert_eq!(t[1]["result"], "abort 0x06020000");
    assert_eq!(t[2]["result"], "abort 0x06010002");
    let abort = &frames(&records)[11];
    assert_eq!(abort["command"], "abort");
    assert!(
        abort["text"]
            .as_str()
            .unwrap()
            .contains("attempt to write a read only object"),
        "{abort}"
    );
}

#[test]
fn a_trace_that_starts_in_the_middle_of_a_transfer() {
    let trace = "\
5A8#1041435334302020
628#7000000000000000
5A8#1B36300000000000
628#4018100100000000
5A8#4318100178563412
";
    let records = decode(&mut bare(), trace);
    let f = frames(&records);
    assert!(
        f[0]["text"]
            .as_str()
            .unwrap()
            .contains("whose start is not in the trace"),
        "{}",
        f[0]
    );
    // The next transfer is reassembled as usual.
    let t = transfers(&records);
    assert_eq!(t.len(), 1, "{records:#?}");
    assert_eq!(t[0]["data"], "78563412");
}

#[test]
fn pdo_mapping_changed_by_the_traces_sdo_writes() {
    let mut decoder = Decoder::new();
    decoder.add_node(40, seed("zimmer_acs"));
    // TPDO2 of node 40: disabled, mapping cleared, then 0x6064 (position
    // actual value, 32 bits) and 0x6041 (statusword, 16 bits), enabled.
    let trace = "\
2A8#10000000
628#23011801A8020080
5A8#6001180100000000
628#2F011A0000000000
5A8#60011A0000000000
628#23011A0120006460
5A8#60011A0100000000
628#23011A0210004160
5A8#60011A0200000000
628#2F011A0002000000
5A8#60011A0000000000
628#23011801A8020000
5A8#6001180100000000
2A8#FEFFFFFF3706
";
    let records = decode(&mut decoder, trace);
    let f = frames(&records);
    // Before: the default TPDO2 (velocity actual value).
    assert_eq!(f[0]["pdo"], "tpdo2");
    assert_eq!(f[0]["fields"].as_array().unwrap().len(), 1, "{}", f[0]);
    // After: the new mapping, by name, signed.
    let last = f.last().unwrap();
    assert_eq!(last["pdo"], "tpdo2");
    let fields = last["fields"].as_array().unwrap();
    assert_eq!(fields.len(), 2, "{last}");
    assert_eq!(fields[0]["raw"], -2, "{last}");
    assert_eq!(fields[1]["raw"], 0x0637);
    assert!(
        fields[1]["name"]
            .as_str()
            .unwrap()
            .to_lowercase()
            .contains("status"),
        "{last}"
    );
    let _ = field(last, fields[0]["name"].as_str().unwrap());
    assert_eq!(transfers(&records).len(), 6);
}
