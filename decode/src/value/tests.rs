use super::*;
use eds2rust::ir::{NamedValue, Origin};

#[test]
fn integers_round_trip_by_type() {
    for (t, v) in [
        (DataType::Unsigned8, 200),
        (DataType::Integer8, -5),
        (DataType::Integer24, -0x7F_FFFF),
        (DataType::Unsigned64, u64::MAX as i128),
        (DataType::Integer64, i64::MIN as i128),
        (DataType::Boolean, 1),
    ] {
        let bytes = encode(t, &Decoded::Int(v)).unwrap();
        assert_eq!(bytes.len(), fixed_size(t).unwrap());
        assert_eq!(decode(t, &bytes).unwrap(), (Decoded::Int(v), None), "{t:?}");
    }
    assert!(encode(DataType::Unsigned8, &Decoded::Int(256)).is_err());
    assert!(encode(DataType::Integer8, &Decoded::Int(-129)).is_err());
    let (v, note) = decode(DataType::Unsigned8, &[7, 0, 0, 0]).unwrap();
    assert_eq!(v, Decoded::Int(7));
    assert!(note.unwrap().contains("4 bytes"));
    assert!(decode(DataType::Unsigned16, &[7]).is_err());
}

#[test]
fn parse_and_describe_with_semantics() {
    let origin = Origin::default();
    let sem = Semantics {
        unit: Some("mm".into()),
        scale: Some(0.1),
        values: Some(ValueTable {
            numeric: Some((0, 0xFAFF)),
            named: vec![NamedValue {
                low: 0xFB00,
                high: 0xFB00,
                name: "clear error".into(),
                text: None,
                rust_name: None,
                origin,
            }],
            other: "invalid".into(),
        }),
        ..Semantics::default()
    };
    let t = DataType::Unsigned16;
    assert_eq!(parse(t, &sem, "12.5 mm").unwrap(), Decoded::Int(125));
    assert_eq!(parse(t, &sem, "12.5mm").unwrap(), Decoded::Int(125));
    assert_eq!(parse(t, &sem, "0x7D").unwrap(), Decoded::Int(125));
    assert_eq!(parse(t, &sem, "Clear Error").unwrap(), Decoded::Int(0xFB00));
    assert!(parse(t, &sem, "12.55 mm").is_err());
    assert_eq!(
        describe(t, &sem, &Decoded::Int(125)),
        "125 (0x007D) = 12.5 mm"
    );
    assert_eq!(
        describe(t, &sem, &Decoded::Int(0xFB00)),
        "64256 (0xFB00) \"clear error\""
    );
    assert_eq!(
        describe(t, &sem, &Decoded::Int(0xFC00)),
        "64512 (0xFC00) \"invalid\""
    );
}

#[test]
fn strings_bytes_and_types() {
    let none = Semantics::default();
    assert_eq!(
        parse(DataType::OctetString, &none, "01 0a FF").unwrap(),
        Decoded::Bytes(vec![1, 10, 255])
    );
    assert!(parse_hex("0").is_err());
    assert_eq!(
        decode(DataType::VisibleString, b"ab\0\0").unwrap().0,
        Decoded::Text("ab".into())
    );
    assert!(encode(DataType::VisibleString, &Decoded::Text("é".into())).is_err());
    assert_eq!(parse_type("U16").unwrap(), DataType::Unsigned16);
    assert_eq!(parse_type("UNSIGNED16").unwrap(), DataType::Unsigned16);
    assert!(parse_type("u12").is_err());
    assert_eq!(parse_int("-0x10"), Some(-16));
    assert_eq!(parse_int("1_000"), Some(1000));
    assert_eq!(parse_int("abc"), None);
    assert_eq!(
        describe(DataType::Real32, &none, &Decoded::Real(f64::from(0.1f32))),
        "0.1"
    );
}

#[test]
fn errors_are_typed_and_say_what_is_wrong() {
    let none = Semantics::default();
    let e = decode(DataType::Unsigned16, &[7]).unwrap_err();
    assert_eq!(
        e,
        ValueError::TooShort {
            data_type: DataType::Unsigned16,
            data: vec![7],
            size: 2
        }
    );
    assert_eq!(
        e.to_string(),
        "1 bytes (07) cannot be a UNSIGNED16 (2 bytes)"
    );
    let e = decode(DataType::Boolean, &[2]).unwrap_err();
    assert_eq!(e.to_string(), "0x02 is not a BOOLEAN (0 or 1)");
    let e = encode(DataType::Unsigned8, &Decoded::Int(256)).unwrap_err();
    assert_eq!(
        e.to_string(),
        "256 is outside the range of UNSIGNED8 (0 to 255)"
    );
    let e = encode(DataType::Unsigned8, &Decoded::Text("a".into())).unwrap_err();
    assert_eq!(e.to_string(), "Text(\"a\") is not a value of UNSIGNED8");
    let e = parse(DataType::Boolean, &none, "maybe").unwrap_err();
    assert_eq!(
        e.to_string(),
        "`maybe` is not a BOOLEAN (true, false, 1 or 0)"
    );
    let e = parse(DataType::Unsigned8, &none, "ten").unwrap_err();
    assert_eq!(e.to_string(), "`ten` is not valid for UNSIGNED8");
    let e = parse_type("u12").unwrap_err();
    assert_eq!(e.name, "u12");
    assert!(
        e.to_string().starts_with("`u12` is not a type: u8 u16"),
        "{e}"
    );
}
