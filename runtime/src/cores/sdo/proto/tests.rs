use super::*;

#[test]
fn expedited_download_of_two_bytes() {
    // Written from CiA 301: ccs=1, n=2, e=1, s=1 -> 0x2B.
    let r = Request::DownloadInitiate {
        index: 0x1017,
        sub: 0,
        data: Initiate::Expedited {
            data: [0xE8, 0x03, 0, 0],
            len: Some(2),
        },
    };
    assert_eq!(r.encode(), [0x2B, 0x17, 0x10, 0x00, 0xE8, 0x03, 0, 0]);
    assert_eq!(Request::parse(&r.encode()), Ok(r));
}

#[test]
fn known_command_bytes() {
    assert_eq!(
        Request::UploadInitiate {
            index: 0x1000,
            sub: 0
        }
        .encode()[0],
        0x40
    );
    assert_eq!(
        Response::DownloadInitiate { index: 1, sub: 0 }.encode()[0],
        0x60
    );
    // Expedited upload response of 4 bytes: 0x43.
    let r = Response::UploadInitiate {
        index: 0x1000,
        sub: 0,
        data: Initiate::Expedited {
            data: [0x92, 0x01, 0x02, 0x00],
            len: Some(4),
        },
    };
    assert_eq!(r.encode(), [0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00]);
    // Segmented upload response with size: 0x41.
    let r = Response::UploadInitiate {
        index: 0x1008,
        sub: 0,
        data: Initiate::Segmented { size: Some(10) },
    };
    assert_eq!(r.encode(), [0x41, 0x08, 0x10, 0x00, 10, 0, 0, 0]);
    // Last upload segment with 3 bytes, toggle 1: 0x1 << 4 | (7-3) << 1 | 1 = 0x19.
    let r = Response::UploadSegment {
        toggle: true,
        last: true,
        data: [1, 2, 3, 0, 0, 0, 0],
        len: 3,
    };
    assert_eq!(r.encode(), [0x19, 1, 2, 3, 0, 0, 0, 0]);
    assert_eq!(Request::BlockUploadStart.encode()[0], 0xA3);
    let r = Request::BlockDownloadInitiate {
        index: 0x1F50,
        sub: 1,
        crc: true,
        size: Some(0x100),
    };
    assert_eq!(r.encode(), [0xC6, 0x50, 0x1F, 0x01, 0x00, 0x01, 0x00, 0x00]);
    let a = Request::Abort {
        index: 0x2000,
        sub: 1,
        code: AbortCode::WriteReadOnly,
    };
    assert_eq!(a.encode(), [0x80, 0x00, 0x20, 0x01, 0x02, 0x00, 0x01, 0x06]);
}

#[test]
fn crc_matches_the_ccitt_check_value() {
    // The CRC catalogue's check value of CRC-16/XMODEM over "123456789".
    assert_eq!(CRC.checksum(b"123456789"), 0x31C3);
}

#[test]
fn wrong_length_and_unknown_commands_are_errors() {
    assert_eq!(Request::parse(&[0x40, 0, 0]), Err(ParseError::Length(3)));
    assert_eq!(
        Request::parse(&[0xE0, 0, 0, 0, 0, 0, 0, 0]),
        Err(ParseError::Command(0xE0))
    );
    assert_eq!(
        Response::parse(&[0xA3, 0, 0, 0, 0, 0, 0, 0]),
        Err(ParseError::Command(0xA3))
    );
    assert_eq!(
        BlockSegment::parse(&[0x80, 0, 0, 0, 0, 0, 0, 0]),
        Err(ParseError::Field(0x80))
    );
}

#[test]
fn every_response_parses_from_the_bytes_its_command_needs() {
    let responses = [
        Response::DownloadInitiate {
            index: 0x6040,
            sub: 0,
        },
        Response::DownloadSegment { toggle: true },
        Response::UploadInitiate {
            index: 0x1001,
            sub: 0,
            data: Initiate::Expedited {
                data: [5, 0, 0, 0],
                len: Some(1),
            },
        },
        Response::UploadInitiate {
            index: 0x1001,
            sub: 0,
            data: Initiate::Expedited {
                data: [5, 6, 7, 8],
                len: None,
            },
        },
        Response::UploadInitiate {
            index: 0x1008,
            sub: 0,
            data: Initiate::Segmented { size: Some(12) },
        },
        Response::UploadInitiate {
            index: 0x1008,
            sub: 0,
            data: Initiate::Segmented { size: None },
        },
        Response::UploadSegment {
            toggle: false,
            last: true,
            data: [1, 2, 0, 0, 0, 0, 0],
            len: 2,
        },
        Response::Abort {
            index: 0x1000,
            sub: 0,
            code: AbortCode::Timeout,
        },
        Response::BlockDownloadInitiate {
            index: 0x1F50,
            sub: 1,
            crc: true,
            block_size: 127,
        },
        Response::BlockDownloadAck {
            ack_seq: 3,
            block_size: 127,
        },
        Response::BlockDownloadEnd,
        Response::BlockUploadInitiate {
            index: 0x1F50,
            sub: 1,
            crc: true,
            size: Some(900),
        },
        Response::BlockUploadInitiate {
            index: 0x1F50,
            sub: 1,
            crc: false,
            size: None,
        },
        Response::BlockUploadEnd {
            unused: 3,
            crc: 0xBEEF,
        },
    ];
    for response in responses {
        let bytes = response.encode();
        let needed = response_len(bytes[0]);
        assert_eq!(
            Response::parse(&bytes[..needed]),
            Ok(response),
            "{bytes:02X?}"
        );
        assert_eq!(
            Response::parse(&bytes[..needed - 1]),
            Err(ParseError::Short {
                len: needed - 1,
                needed
            }),
            "{bytes:02X?}"
        );
    }
}
