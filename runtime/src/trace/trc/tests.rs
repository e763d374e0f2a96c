use super::*;
use crate::CanId;
use crate::trace::test_support::{ext_frame, std_frame};

fn ms(millis: u64, micros: u64) -> Duration {
    Duration::from_millis(millis) + Duration::from_micros(micros)
}

fn frame(time: Duration, frame: Frame) -> Record {
    Record {
        time,
        message: Message::Frame(frame),
    }
}

fn other(time: Duration, other: Other) -> Record {
    Record {
        time,
        message: Message::Other(other),
    }
}

/// A parser that has read `header` (one directive a line).
fn after(header: &str) -> Parser {
    let mut parser = Parser::new();
    for line in header.lines() {
        assert_eq!(parser.parse_line(line), Ok(None), "{line}");
    }
    parser
}

fn message(parser: &Parser, line: &str) -> Record {
    parser
        .parse_message(line)
        .unwrap_or_else(|e| panic!("{line}: {e}"))
}

#[test]
fn versions() {
    for v in [
        Version::V1_0,
        Version::V1_1,
        Version::V1_2,
        Version::V1_3,
        Version::V2_0,
        Version::V2_1,
    ] {
        assert_eq!(Version::parse(v.as_str()), Some(v));
        assert_eq!(v.to_string(), v.as_str());
    }
    assert_eq!(Version::parse("3.0"), None);
    assert_eq!(Version::parse(""), None);
}

#[test]
fn version_1_0() {
    let p = after(";##########\n;   recorded by hand\n");
    assert_eq!(
        message(&p, "     1)      2210      0181  4  A0 0F 00 12"),
        frame(ms(2210, 0), std_frame(0x181, &[0xA0, 0x0F, 0x00, 0x12]))
    );
    assert_eq!(
        message(&p, "    17)      2305  18FF50E5  2  7F 01"),
        frame(ms(2305, 0), ext_frame(0x18FF_50E5, &[0x7F, 0x01]))
    );
    assert_eq!(
        message(&p, "    18)      2306      0701  1  RTR"),
        frame(
            ms(2306, 0),
            Frame::remote(CanId::Standard(0x701), 1).unwrap()
        )
    );
    assert_eq!(
        message(&p, "    19)      2307      0080  0"),
        frame(ms(2307, 0), std_frame(0x80, &[]))
    );
    assert_eq!(
        message(&p, "    20)      2400      0008  4  ERROR 00 19 08 08"),
        other(ms(2400, 0), Other::ErrorFrame)
    );
    assert_eq!(
        message(
            &p,
            "    21)      2401  FFFFFFFF  4  00 00 00 04 -- -- -- --  BUSLIGHT"
        ),
        other(ms(2401, 0), Other::BusWarning)
    );
}

#[test]
fn version_1_1() {
    let p = after(";$FILEVERSION=1.1\n;$STARTTIME=45292.5\n;   a comment\n");
    assert_eq!(p.version(), Some(Version::V1_1));
    assert_eq!(
        message(
            &p,
            "     3)      4711.3  Rx         0581  8  43 00 10 00 92 01 02 00"
        ),
        frame(
            ms(4711, 300),
            std_frame(0x581, &[0x43, 0, 0x10, 0, 0x92, 1, 2, 0])
        )
    );
    assert_eq!(
        message(&p, "     4)      4712.0  Tx     1CEBFF00  3  01 02 03"),
        frame(ms(4712, 0), ext_frame(0x1CEB_FF00, &[1, 2, 3]))
    );
    assert_eq!(
        message(&p, "     5)      4713.9  Tx         0705  0  RTR"),
        frame(
            ms(4713, 900),
            Frame::remote(CanId::Standard(0x705), 0).unwrap()
        )
    );
    assert_eq!(
        message(
            &p,
            "     6)      4720.1  Warng  FFFFFFFF  4  00 00 00 08  BUSHEAVY"
        ),
        other(ms(4720, 100), Other::BusWarning)
    );
    assert_eq!(
        message(&p, "     7)      4721.5  Error      0008  4  00 19 08 08"),
        other(ms(4721, 500), Other::ErrorFrame)
    );
}

#[test]
fn versions_1_2_and_1_3() {
    let p = after(";$FILEVERSION=1.2\n;$STARTTIME=45292.5;\n");
    assert_eq!(
        message(&p, "     1)       310.250  2  Rx         0202  2  E8 03"),
        frame(ms(310, 250), std_frame(0x202, &[0xE8, 0x03]))
    );
    assert_eq!(
        p.parse_message("     1)       310.250  Rx  0202  2  E8 03"),
        Err(Reason::BadBus)
    );
    let p = after(";$FILEVERSION=1.3\n;$STARTTIME=45292.5\n");
    assert_eq!(
        message(&p, "     1)       310.250 1  Rx        0202 -  2    E8 03"),
        frame(ms(310, 250), std_frame(0x202, &[0xE8, 0x03]))
    );
    assert_eq!(
        message(&p, "     2)       311.000 1  Tx        0602 -  8    RTR"),
        frame(
            ms(311, 0),
            Frame::remote(CanId::Standard(0x602), 8).unwrap()
        )
    );
    assert_eq!(
        message(
            &p,
            "     3)       312.000 1  Warng FFFFFFFF -  4    00 00 00 04  BUSLIGHT"
        ),
        other(ms(312, 0), Other::BusWarning)
    );
    assert_eq!(
        p.parse_message("     4)       313.000 1  Rx        0202  2    E8 03"),
        Err(Reason::BadReserved)
    );
}

#[test]
fn version_2_0() {
    let p = after(";$FILEVERSION=2.0\n;$STARTTIME=45292.5\n;$COLUMNS=N,O,T,I,d,l,D\n");
    assert_eq!(p.columns(), Some(Columns::V2_0));
    assert_eq!(
        message(&p, "     12      5012.345 DT     0181 Rx 4  01 02 03 04"),
        frame(ms(5012, 345), std_frame(0x181, &[1, 2, 3, 4]))
    );
    assert_eq!(
        message(
            &p,
            "     13      5013.000 DT 0CF00400 Rx 8  F0 7D 7D 00 00 00 F0 7D"
        ),
        frame(
            ms(5013, 0),
            ext_frame(0x0CF0_0400, &[0xF0, 0x7D, 0x7D, 0, 0, 0, 0xF0, 0x7D])
        )
    );
    assert_eq!(
        message(&p, "     14      5014.500 RR     0281 Tx 6"),
        frame(
            ms(5014, 500),
            Frame::remote(CanId::Standard(0x281), 6).unwrap()
        )
    );
    // Other messages leave columns empty; they are recognised by type.
    let notes = [
        (
            "     15      5015.000 FD     0300 Tx 12 01 02 03 04 05 06 07 08 09 0A 0B 0C",
            Other::CanFd,
        ),
        (
            "     16      5016.000 ER          Rx    04 00 02 00 00",
            Other::ErrorFrame,
        ),
        (
            "     17      5017.000 ST          Rx    00 00 00 08",
            Other::Status,
        ),
        (
            "     18      5018.000 EC          Rx    02 02",
            Other::ErrorCounter,
        ),
    ];
    for (line, kind) in notes {
        assert_eq!(message(&p, line).message, Message::Other(kind), "{line}");
    }
}

#[test]
fn version_2_1() {
    let p = after(";$FILEVERSION=2.1\n;$STARTTIME=45292.5\n;$COLUMNS=N,O,T,B,I,d,R,L,D\n");
    assert_eq!(
        message(&p, "      1       100.125 DT 1      0701 Rx -  1    05"),
        frame(ms(100, 125), std_frame(0x701, &[0x05]))
    );
    assert_eq!(
        message(
            &p,
            "      2       100.500 DT 2  18DA00F1 Tx -  3    02 10 03"
        ),
        frame(ms(100, 500), ext_frame(0x18DA_00F1, &[2, 0x10, 3]))
    );
    assert_eq!(
        message(&p, "      3       101.000 RR 1      0181 Tx -  8"),
        frame(
            ms(101, 0),
            Frame::remote(CanId::Standard(0x181), 8).unwrap()
        )
    );
    let notes = [
        (
            "      4       102.000 FB 1      0300 Tx -  9    01 02 03 04 05 06 07 08 09 0A 0B 0C",
            Other::CanFd,
        ),
        (
            "      5       102.500 ER 1         - Rx -  5    04 00 02 00 00",
            Other::ErrorFrame,
        ),
        (
            "      6       103.000 EV 1  Start of the test run",
            Other::Event,
        ),
        (
            "      7       103.100 EV -  Note for every bus",
            Other::Event,
        ),
        (
            "      8       103.200 ST 1         - Rx -  4    00 00 00 08",
            Other::Status,
        ),
        (
            "      9       103.300 BI 1      0300 Rx -  2    01 02",
            Other::CanFd,
        ),
    ];
    for (line, kind) in notes {
        assert_eq!(message(&p, line).message, Message::Other(kind), "{line}");
    }
    // Without $COLUMNS the default of the version applies.
    let p = after(";$FILEVERSION=2.1\n");
    assert_eq!(p.columns(), None);
    assert_eq!(
        message(&p, "      1       100.125 DT 1      0701 Rx -  1    05"),
        frame(ms(100, 125), std_frame(0x701, &[0x05]))
    );
}

#[test]
fn custom_columns() {
    let p = after(";$FILEVERSION=2.0\n;$COLUMNS=O,T,I,L,D\n");
    assert_eq!(p.columns().unwrap().to_string(), "O,T,I,L,D");
    assert_eq!(
        message(&p, "  7.000 DT 0123 2 AA BB"),
        frame(ms(7, 0), std_frame(0x123, &[0xAA, 0xBB]))
    );
    let bad = [
        ("N,O,T,I,X,L,D", "unknown column letter"),
        (
            "N,O,I,T,L,D",
            "columns repeated or out of the order N,O,T,B,I,d,R,L,D",
        ),
        (
            "N,O,T,I,L,l,D",
            "columns repeated or out of the order N,O,T,B,I,d,R,L,D",
        ),
        (
            "N,O,T,I,D,L",
            "columns repeated or out of the order N,O,T,B,I,d,R,L,D",
        ),
        ("N,O,T,I,D", "expected at least O, T, I, L (or l) and D"),
        ("", "unknown column letter"),
    ];
    for (list, why) in bad {
        assert_eq!(Columns::parse(list), Err(Reason::BadColumns(why)), "{list}");
    }
}

#[test]
fn shapes_without_header() {
    let p = Parser::new();
    let data = std_frame(0x300, &[0x11, 0x22]);
    for line in [
        "     1)      1841  0300  2  11 22",
        "     1)      1841.0  Rx  0300  2  11 22",
        "     1)      1841.000  1  Rx  0300  2  11 22",
        "     1)      1841.000 1  Rx  0300 -  2  11 22",
        "     1)      1841  0300 -  2  11 22",
        "     1      1841.000 DT     0300 Rx 2  11 22",
        "     1      1841.000 DT 1      0300 Rx -  2  11 22",
        "     1      1841.000 DT -      0300 Rx -  2  11 22",
        "  1841.000 DT 1      0300 Rx -  2  11 22",
        "  1841.000 DT     0300 Rx 2  11 22",
    ] {
        assert_eq!(message(&p, line), frame(ms(1841, 0), data), "{line}");
    }
}

#[test]
fn time_offsets() {
    let p = Parser::new();
    let time = |offset: &str| {
        p.parse_message(&format!("1) {offset} 0001 0"))
            .map(|record| record.time)
    };
    assert_eq!(time("0"), Ok(Duration::ZERO));
    assert_eq!(time("1059.9"), Ok(ms(1059, 900)));
    assert_eq!(time("1059.900"), Ok(ms(1059, 900)));
    assert_eq!(time("1059."), Ok(ms(1059, 0)));
    assert_eq!(time("3.1234567"), Ok(Duration::new(0, 3_123_456)));
    assert_eq!(time("86400000.001"), Ok(Duration::new(86_400, 1_000)));
    for bad in ["-1.0", "1,5", ".5", "1.5e3", "99999999999999999999"] {
        assert_eq!(time(bad), Err(Reason::BadOffset), "{bad}");
    }
}

#[test]
fn start_time() {
    // 2024-01-01 12:00 UTC is day 45292.5 since 1899-12-30.
    let p = after(";$FILEVERSION=1.1\n;$STARTTIME=45292.5\n");
    assert_eq!(p.start_time(), Some(Duration::from_secs(1_704_110_400)));
    let p = after(";$STARTTIME=25569.25;\n");
    assert_eq!(p.start_time(), Some(Duration::from_secs(6 * 3600)));
    // Before 1970: no start time, but no error either.
    let p = after(";$STARTTIME=0\n");
    assert_eq!(p.start_time(), None);
    let mut p = Parser::new();
    for bad in ["", "abc", "-1", "1e5", "inf", "NaN"] {
        let line = format!(";$STARTTIME={bad}");
        assert_eq!(p.parse_line(&line), Err(Reason::BadStartTime), "{line}");
    }
    // A new $FILEVERSION starts a new header.
    let mut p = after(";$FILEVERSION=2.1\n;$STARTTIME=45292.5\n;$COLUMNS=O,T,I,L,D\n");
    assert_eq!(p.parse_line(";$FILEVERSION=2.0"), Ok(None));
    assert_eq!((p.start_time(), p.columns()), (None, None));
    assert_eq!(
        p.parse_line(";$FILEVERSION=9.9"),
        Err(Reason::UnknownVersion)
    );
    assert_eq!(p.version(), None);
}

#[test]
fn comments_and_other_directives() {
    let mut p = Parser::new();
    for line in [
        ";",
        ";   Start time: 01.01.2024 12:00:00.000.0",
        ";$",
        ";$UNKNOWN=1",
        ";$ NOT A DIRECTIVE",
        "   ;---+-- ------+------ +- --+-----",
        "",
        "   ",
    ] {
        assert_eq!(p.parse_line(line), Ok(None), "{line:?}");
    }
    assert_eq!(p.version(), None);
    assert_eq!(p.parse_line(" ;$fileversion = 1.3 "), Ok(None));
    assert_eq!(p.version(), Some(Version::V1_3));
}

#[test]
fn malformed_lines() {
    let v11 = after(";$FILEVERSION=1.1\n");
    let v21 = after(";$FILEVERSION=2.1\n");
    let cases: [(&Parser, &str, Reason); 20] = [
        (&v11, "x) 1.0 Rx 0100 0", Reason::BadNumber),
        (&v11, "1)", Reason::Missing("time offset")),
        (&v11, "1) 1.0", Reason::Missing("message type")),
        (&v11, "1) 1.0 Rq 0100 0", Reason::BadType),
        (&v11, "1) 1.0 Rx", Reason::Missing("identifier")),
        (&v11, "1) 1.0 Rx 01G0 0", Reason::BadIdentifier),
        (&v11, "1) 1.0 Rx 123456789 0", Reason::BadIdentifier),
        (
            &v11,
            "1) 1.0 Rx 0800 0",
            Reason::IdentifierOutOfRange(0x800),
        ),
        (
            &v11,
            "1) 1.0 Rx 20000000 0",
            Reason::IdentifierOutOfRange(0x2000_0000),
        ),
        (&v11, "1) 1.0 Rx 0100", Reason::Missing("data length code")),
        (
            &v11,
            "1) 1.0 Rx 0100 9 01 02 03 04 05 06 07 08 09",
            Reason::BadLength,
        ),
        (
            &v11,
            "1) 1.0 Rx 0100 3 01 02",
            Reason::LengthMismatch {
                declared: 3,
                actual: 2,
            },
        ),
        (
            &v11,
            "1) 1.0 Rx 0100 1 01 02",
            Reason::LengthMismatch {
                declared: 1,
                actual: 2,
            },
        ),
        (&v11, "1) 1.0 Rx 0100 2 01 2", Reason::BadData),
        (&v11, "1) 1.0 Rx 0100 2 RTR 01", Reason::Trailing),
        (&v21, "1 1.000 XX 1 0100 Rx - 0", Reason::UnknownType),
        (&v21, "1 1.000 DT x 0100 Rx - 0", Reason::BadBus),
        (&v21, "1 1.000 DT 1 0100 Up - 0", Reason::BadDirection),
        (&v21, "1 1.000 DT 1 0100 Rx + 0", Reason::BadReserved),
        (&v21, "1 1.000 RR 1 0100 Rx - 2 01 02", Reason::Trailing),
    ];
    for (parser, line, reason) in cases {
        assert_eq!(parser.parse_message(line), Err(reason), "{line}");
    }
    assert_eq!(
        v21.parse_message("1 1.000 DT 1 0100 Rx - 2 01"),
        Err(Reason::LengthMismatch {
            declared: 2,
            actual: 1
        })
    );
}

#[test]
fn message_line_shapes() {
    for line in ["1) 2 0100 0", "  12 1.000 DT", "1059.900 DT", "7"] {
        assert!(is_message_line(line), "{line}");
    }
    for line in [
        "",
        "  ",
        "can0 123 [1] 00",
        "123#00",
        "(1.0) can0 123#",
        "x) 1",
        "1.2.3 DT",
        ")",
        "; comment",
    ] {
        assert!(!is_message_line(line), "{line}");
    }
}

#[test]
fn reasons_say_what_was_expected() {
    assert_eq!(
        Reason::BadType.to_string(),
        "bad message type: expected Rx, Tx, Warng or Error"
    );
    assert_eq!(
        Reason::Missing("identifier").to_string(),
        "the trace line ends before the identifier"
    );
    assert_eq!(Other::CanFd.to_string(), "CAN FD frame");
}
