//! The client under random server frames, timeouts and local aborts.

use super::*;

/// Random server frames in every phase: no panic, no hang, bounded memory,
/// one event per transfer.
#[test]
fn random_server_frames() {
    let mut seed = 0x2545_F491_4F6C_DD1Du64;
    let mut random = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    let mut c = SdoClient::new(ClientConfig {
        max_upload: 64,
        block_size: 3,
        ..config()
    });
    let mut now = 0u64;
    let mut finished = 0;
    for round in 0..20_000 {
        if c.is_idle() {
            let method = [Method::Auto, Method::Segmented, Method::Block][round % 3];
            let len = (random() % 40) as usize;
            let started = if random() % 2 == 0 {
                c.upload_with(ms(now), 0x2000, 0, method)
            } else {
                c.download_with(ms(now), 0x2000, 0, &vec![0x5A; len], method)
            };
            assert_eq!(started, Ok(()));
        }
        let bits = random();
        let mut bytes = bits.to_le_bytes();
        // Often a plausible command byte for this object.
        if bits % 3 == 0 {
            bytes[1..4].copy_from_slice(&[0x00, 0x20, 0x00]);
        }
        now += random() % 300;
        match bits % 11 {
            0 => c.handle_timeout(ms(now)),
            1 => c.abort(AbortCode::GeneralError),
            _ => reply(&mut c, ms(now), bytes),
        }
        while c.poll_transmit().is_some() {}
        while let Some(event) = c.poll_event() {
            finished += 1;
            if let ClientEvent::Uploaded { data, .. } = event {
                assert!(data.len() <= 64);
            }
        }
        assert!(c.buf.capacity() <= 64);
        if c.is_idle() {
            assert_eq!(c.poll_timeout(), None);
        }
    }
    assert!(finished > 1000);
}
