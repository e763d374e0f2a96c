use super::*;
use crate::trace::test_support::{Rng, std_frame};

fn ts(secs: u64, micros: u32) -> Duration {
    Duration::new(secs, micros * 1000)
}

fn parse(line: &str) -> LogLine {
    parse_line(line).unwrap().unwrap()
}

#[test]
fn log_form() {
    assert_eq!(
        parse("(1436509052.249713) vcan0 123#11223344"),
        LogLine::new(
            ts(1436509052, 249713),
            "vcan0",
            std_frame(0x123, &[0x11, 0x22, 0x33, 0x44])
        )
    );
    let ext = parse("(0.000001) can1 12345678#DEADBEEF00");
    assert_eq!(
        ext.frame,
        Frame::new(CanId::Extended(0x1234_5678), &[0xDE, 0xAD, 0xBE, 0xEF, 0]).unwrap()
    );
    assert_eq!(ext.timestamp, Some(Duration::from_micros(1)));
    assert_eq!(
        parse("(1.5) can0 701#R").frame,
        Frame::remote(CanId::Standard(0x701), 0).unwrap()
    );
    assert_eq!(
        parse("(1.5) can0 701#R").timestamp,
        Some(Duration::from_millis(1500))
    );
    assert_eq!(
        parse("(2.000000) can0 701#R5").frame,
        Frame::remote(CanId::Standard(0x701), 5).unwrap()
    );
    assert_eq!(parse("(3.0) can0 000#").frame, std_frame(0, &[]));
    assert_eq!(
        parse("(3.0) can0 601#40.17.10.00").frame,
        std_frame(0x601, &[0x40, 0x17, 0x10, 0])
    );
    assert_eq!(parse("(3.0) can0 1ff#ab").frame, std_frame(0x1FF, &[0xAB]));
    assert_eq!(
        parse("(1436509052.123456789) vcan0 123#").timestamp,
        Some(Duration::new(1436509052, 123_456_789))
    );
}

#[test]
fn text_form() {
    let line = parse("  vcan0  123   [4]  11 22 33 44");
    assert_eq!(line.timestamp, None);
    assert_eq!(line.interface, "vcan0");
    assert_eq!(line.frame, std_frame(0x123, &[0x11, 0x22, 0x33, 0x44]));
    assert_eq!(
        parse("  vcan0  123   [0]  remote request").frame,
        Frame::remote(CanId::Standard(0x123), 0).unwrap()
    );
    assert_eq!(
        parse("  can0  701   [1]  remote request").frame,
        Frame::remote(CanId::Standard(0x701), 1).unwrap()
    );
    assert_eq!(
        parse("  can0  1ABCDEF0   [2]  01 02").frame,
        Frame::new(CanId::Extended(0x1ABC_DEF0), &[1, 2]).unwrap()
    );
    assert_eq!(parse("  can0  080   [0]").frame, std_frame(0x80, &[]));
    let stamped = parse(" (1436509052.249713)  vcan0  123   [2]  11 22");
    assert_eq!(stamped.timestamp, Some(ts(1436509052, 249713)));
    assert_eq!(stamped.frame, std_frame(0x123, &[0x11, 0x22]));
}

#[test]
fn compact_form() {
    let line = parse("123#11223344");
    assert_eq!(line.timestamp, None);
    assert_eq!(line.interface, "");
    assert_eq!(line.frame, std_frame(0x123, &[0x11, 0x22, 0x33, 0x44]));
    // Whatever Frame's Display writes parses back.
    for frame in [
        std_frame(0x220, &[3, 0xFB, 0xFB, 0xFB, 0xFB, 0xFB, 0, 0]),
        Frame::remote(CanId::Standard(0x720), 1).unwrap(),
        Frame::new(CanId::Extended(0x1234), &[]).unwrap(),
    ] {
        assert_eq!(parse_frame(&frame.to_string()), Ok(frame));
    }
}

#[test]
fn blank_lines_are_skipped() {
    assert_eq!(parse_line(""), Ok(None));
    assert_eq!(parse_line("  \t "), Ok(None));
}

#[test]
fn errors_name_the_problem() {
    let cases: &[(&str, Reason)] = &[
        ("(1.0) can0 12#11", Reason::BadIdentifier),
        ("(1.0) can0 1234#11", Reason::BadIdentifier),
        ("(1.0) can0 +12#11", Reason::BadIdentifier),
        ("(1.0) can0 800#11", Reason::IdentifierOutOfRange(0x800)),
        (
            "(1.0) can0 20000000#11",
            Reason::IdentifierOutOfRange(0x2000_0000),
        ),
        ("(1.0) can0 123#1", Reason::BadData),
        ("(1.0) can0 123#1G", Reason::BadData),
        ("(1.0) can0 123#112233445566778899", Reason::TooManyBytes(9)),
        ("(1.0) can0 123#R9", Reason::BadLength),
        ("(1.0) can0 123##1112233", Reason::CanFd),
        ("(1.0x) can0 123#11", Reason::BadTimestamp),
        ("(1.0 can0 123#11", Reason::BadTimestamp),
        ("(1.0123456789) can0 123#11", Reason::BadTimestamp),
        (
            "(99999999999999999999999.0) can0 123#11",
            Reason::BadTimestamp,
        ),
        ("(1.0)", Reason::Missing("interface")),
        ("(1.0) can0", Reason::Missing("frame")),
        ("(1.0) can0 123#11 extra", Reason::Trailing),
        (
            "  can0  123   [3]  11 22",
            Reason::LengthMismatch {
                declared: 3,
                actual: 2,
            },
        ),
        ("  can0  123   [9]  11", Reason::BadLength),
        ("  can0  123   4  11", Reason::BadLength),
        ("  can0  123", Reason::Missing("length")),
        ("  can0  123   [2]  11 2", Reason::BadData),
        ("  can0  123   [0]  remote", Reason::BadData),
        ("  can0  123   [0]  remote request now", Reason::Trailing),
        ("  can0  123   [8]  1 2 3 4 5 6 7 8 9", Reason::BadData),
        (
            "  can0  123   [8]  01 02 03 04 05 06 07 08 09",
            Reason::TooManyBytes(9),
        ),
    ];
    for (line, reason) in cases {
        assert_eq!(parse_line(line).as_ref().err(), Some(reason), "{line:?}");
    }
    let error = ParseError {
        line: 7,
        reason: Reason::CanFd,
    };
    assert_eq!(
        error.to_string(),
        "line 7: CAN FD frames (##) are not supported"
    );
}

#[test]
fn reader_numbers_lines_and_goes_on_after_errors() {
    let input = "(1.000000) can0 123#01\n\n(bad) can0 123#02\r\n  can0  124   [1]  03\r\n456#\n";
    let items: Vec<_> = Reader::new(input.as_bytes()).collect();
    assert_eq!(items.len(), 4);
    assert_eq!(items[0].as_ref().unwrap().frame, std_frame(0x123, &[1]));
    match &items[1] {
        Err(Error::Parse(e)) => {
            assert_eq!((e.line, &e.reason), (3, &Reason::BadTimestamp));
            assert!(e.to_string().starts_with("line 3: bad timestamp"));
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(items[2].as_ref().unwrap().frame, std_frame(0x124, &[3]));
    assert_eq!(items[3].as_ref().unwrap().frame, std_frame(0x456, &[]));
}

#[test]
fn reader_refuses_long_and_binary_lines() {
    let mut input = Vec::new();
    input.extend_from_slice(&[b'1'; 5000]);
    input.extend_from_slice(b"\n\xFF\xFE\n123#01\n");
    input.extend_from_slice(&[b'x'; MAX_LINE_LEN + 1]);
    let mut reader = Reader::new(&input[..]);
    let reasons: Vec<_> = reader
        .by_ref()
        .map(|r| match r {
            Ok(line) => Ok(line.frame),
            Err(Error::Parse(e)) => Err((e.line, e.reason)),
            Err(Error::Io(e)) => panic!("{e}"),
        })
        .collect();
    assert_eq!(
        reasons,
        [
            Err((1, Reason::TooLong)),
            Err((2, Reason::NotUtf8)),
            Ok(std_frame(0x123, &[1])),
            Err((4, Reason::TooLong)),
        ]
    );
    assert_eq!(reader.line_number(), 4);
}

#[test]
fn writer_forms_round_trip() {
    let lines = [
        LogLine::new(
            ts(1436509052, 249713),
            "vcan0",
            std_frame(0x123, &[0x11, 0x22, 0x33, 0x44]),
        ),
        LogLine::new(
            ts(5, 0),
            "can1",
            Frame::remote(CanId::Standard(0x701), 0).unwrap(),
        ),
        LogLine::new(
            ts(6, 1),
            "can1",
            Frame::remote(CanId::Standard(0x701), 5).unwrap(),
        ),
        LogLine::new(
            ts(7, 2),
            "can0",
            Frame::new(CanId::Extended(0x1FFF_FFFF), &[0xAA]).unwrap(),
        ),
        LogLine::new(ts(8, 3), "can0", std_frame(0x080, &[])),
    ];
    let expected_log = "(1436509052.249713) vcan0 123#11223344\n\
                        (5.000000) can1 701#R\n\
                        (6.000001) can1 701#R5\n\
                        (7.000002) can0 1FFFFFFF#AA\n\
                        (8.000003) can0 080#\n";
    let expected_text = "(1436509052.249713)  vcan0  123   [4]  11 22 33 44\n\
                         (5.000000)  can1  701   [0]  remote request\n\
                         (6.000001)  can1  701   [5]  remote request\n\
                         (7.000002)  can0  1FFFFFFF   [1]  AA\n\
                         (8.000003)  can0  080   [0]\n";
    for (format, expected) in [(Format::Log, expected_log), (Format::Text, expected_text)] {
        let mut writer = Writer::new(Vec::new(), format);
        for line in &lines {
            writer.write(line).unwrap();
        }
        let text = String::from_utf8(writer.into_inner()).unwrap();
        assert_eq!(text, expected);
        let back: Vec<LogLine> = Reader::new(text.as_bytes()).map(Result::unwrap).collect();
        assert_eq!(back, lines);
    }
    let mut writer = Writer::new(Vec::new(), Format::Compact);
    writer.write(&lines[0]).unwrap();
    writer.write_frame(None, "", &lines[3].frame).unwrap();
    assert_eq!(writer.into_inner(), b"123#11223344\n1FFFFFFF#AA\n");
}

#[test]
fn writer_fills_in_missing_parts() {
    let line = LogLine {
        timestamp: None,
        interface: String::new(),
        frame: std_frame(0x181, &[1, 2]),
    };
    assert_eq!(
        line.display(Format::Log).to_string(),
        "(0.000000) can0 181#0102"
    );
    assert_eq!(
        line.display(Format::Text).to_string(),
        "  can0  181   [2]  01 02"
    );
}

#[test]
fn random_input_never_panics() {
    const PIECES: &[&str] = &[
        "(",
        ")",
        ".",
        "#",
        "##",
        "R",
        "r",
        "[",
        "]",
        " ",
        "  ",
        "\t",
        "\r",
        "\n",
        "0",
        "7",
        "8",
        "9",
        "F",
        "f",
        "G",
        "123",
        "7FF",
        "800",
        "1FFFFFFF",
        "FFFFFFFF",
        "remote",
        "request",
        "vcan0",
        "(1436509052.249713)",
        "11",
        "2",
        "-",
        "+",
        "é",
        "\u{0}",
        "99999999999999999999",
        "[8]",
        "[4]",
    ];
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    for _ in 0..20_000 {
        let mut line = String::new();
        for _ in 0..rng.below(12) {
            line.push_str(PIECES[rng.below(PIECES.len())]);
        }
        if let Ok(Some(parsed)) = parse_line(&line) {
            // Whatever parses writes back to a line that parses the same way.
            for format in [Format::Log, Format::Text] {
                let again = parse(&parsed.display(format).to_string());
                assert_eq!(again.frame, parsed.frame, "{line:?}");
            }
        }
        let _ = parse_frame(&line);
    }
    // Raw bytes through the reader.
    for _ in 0..2_000 {
        let bytes: Vec<u8> = (0..rng.below(300)).map(|_| rng.next() as u8).collect();
        for item in Reader::new(&bytes[..]) {
            if let Err(Error::Io(e)) = item {
                panic!("{e}");
            }
        }
    }
}
