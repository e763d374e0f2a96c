//! What real SDO servers send besides the textbook frames: responses
//! shorter than 8 bytes, expedited responses that do not indicate their
//! size. Frames written from the CiA 301 layouts.

use super::*;

/// The server's frame of `bytes` (any length up to 8) reaches the client.
fn reply_short(client: &mut SdoClient, now: Instant, bytes: &[u8]) {
    let frame = Frame::new(CanId::Standard(RESPONSE), bytes).unwrap();
    client.handle_frame(now, &frame);
}

fn uploaded(index: u16, sub: u8, data: &[u8], padded: bool) -> Vec<ClientEvent> {
    vec![ClientEvent::Uploaded {
        index,
        sub,
        data: data.to_vec(),
        padded,
    }]
}

#[test]
fn an_expedited_response_without_size_holds_four_padded_bytes() {
    let mut c = client();
    c.upload(ms(0), 0x6061, 0).unwrap();
    sent(&mut c);
    // 0x42: e=1, s=0. The value (an INTEGER8, say) is the first byte; the
    // client cannot know that, so it hands on all four and says so.
    reply(
        &mut c,
        ms(1),
        [0x42, 0x61, 0x60, 0x00, 0x03, 0x00, 0x00, 0x00],
    );
    assert_eq!(events(&mut c), uploaded(0x6061, 0, &[3, 0, 0, 0], true));
    // The next, sized, upload is not padded.
    c.upload(ms(2), 0x6061, 0).unwrap();
    sent(&mut c);
    reply(
        &mut c,
        ms(3),
        [0x4F, 0x61, 0x60, 0x00, 0x03, 0x00, 0x00, 0x00],
    );
    assert_eq!(events(&mut c), uploaded(0x6061, 0, &[3], false));
}

#[test]
fn short_responses_are_taken_when_every_byte_they_need_is_there() {
    // A 5-byte expedited response for one data byte: 4F = e, s, n=3.
    let mut c = client();
    c.upload(ms(0), 0x1001, 0).unwrap();
    sent(&mut c);
    reply_short(&mut c, ms(1), &[0x4F, 0x01, 0x10, 0x00, 0x05]);
    assert_eq!(events(&mut c), uploaded(0x1001, 0, &[5], false));

    // 6 bytes for two data bytes: 4B = e, s, n=2.
    c.upload(ms(2), 0x6041, 0).unwrap();
    sent(&mut c);
    reply_short(&mut c, ms(3), &[0x4B, 0x41, 0x60, 0x00, 0x37, 0x02]);
    assert_eq!(events(&mut c), uploaded(0x6041, 0, &[0x37, 0x02], false));

    // A 4-byte download initiate response: command, index, sub.
    c.download(ms(4), 0x6040, 0, &[0x0F, 0x00]).unwrap();
    sent(&mut c);
    reply_short(&mut c, ms(5), &[0x60, 0x40, 0x60, 0x00]);
    assert_eq!(
        events(&mut c),
        vec![ClientEvent::Downloaded {
            index: 0x6040,
            sub: 0
        }]
    );

    // A segmented upload whose segments end early: 0x41 with size 9, then
    // a full segment and a last one of 2 bytes in 3 (0x0B: t=0, n=5, c=1
    // would be toggle 0; here the second segment, t=1: 0x1B).
    c.upload(ms(6), 0x1008, 0).unwrap();
    sent(&mut c);
    reply(&mut c, ms(7), [0x41, 0x08, 0x10, 0x00, 9, 0, 0, 0]);
    assert_eq!(one(&mut c), [0x60, 0, 0, 0, 0, 0, 0, 0]);
    reply(
        &mut c,
        ms(8),
        [0x00, b'E', b'C', b'5', b'0', b'0', b'0', b' '],
    );
    assert_eq!(one(&mut c), [0x70, 0, 0, 0, 0, 0, 0, 0]);
    reply_short(&mut c, ms(9), &[0x1B, b'B', b'I']);
    assert_eq!(events(&mut c), uploaded(0x1008, 0, b"EC5000 BI", false));
}

#[test]
fn a_response_shorter_than_its_command_needs_names_the_frame() {
    // 4F announces one data byte at offset 4, the frame ends before it; an
    // abort frame needs its code (8 bytes); an empty frame, its command.
    for (short, needed) in [
        (&[0x4F, 0x01, 0x10, 0x00][..], 5),
        (&[0x80, 0x01, 0x10, 0x00, 0x00, 0x00][..], 8),
        (&[][..], 1),
    ] {
        let mut c = client();
        c.upload(ms(0), 0x1001, 0).unwrap();
        sent(&mut c);
        reply_short(&mut c, ms(1), short);
        if !short.is_empty() {
            assert_eq!(
                one(&mut c),
                [0x80, 0x01, 0x10, 0x00, 0x01, 0x00, 0x04, 0x05]
            );
        }
        let mut frame = [0u8; 8];
        frame[..short.len()].copy_from_slice(short);
        let len = short.len();
        let error = SdoError::BadResponse {
            frame,
            len: len as u8,
            error: ParseError::Short { len, needed },
        };
        assert_eq!(events(&mut c), failed(0x1001, 0, error));
        if len == 4 {
            assert_eq!(
                error.to_string(),
                "the SDO server sent an invalid response [4F 01 10 00]: SDO response has 4 data bytes; \
                 its command needs at least 5; aborted with 0x05040001 (client/server command specifier not valid or unknown)"
            );
        }
    }
}
