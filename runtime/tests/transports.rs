//! Transports through the public API: the virtual bus under threads and
//! load, candump files, and a blocking `drive` loop against a fake peer.

use std::time::Duration;

use eds2rust_runtime::trace::candump::{Format, LogLine, Reader, Writer};
use eds2rust_runtime::transport::Bus;
use eds2rust_runtime::transport::virtual_bus::VirtualBus;
use eds2rust_runtime::{CanId, Frame};

fn frame(id: u16, data: &[u8]) -> Frame {
    Frame::new(CanId::Standard(id), data).unwrap()
}

#[test]
fn concurrent_senders_keep_one_order_for_all_receivers() {
    let bus = VirtualBus::new();
    let rx1 = bus.attach();
    let rx2 = bus.attach();
    let senders: Vec<_> = (0..4u16)
        .map(|t| {
            let port = bus.attach();
            std::thread::spawn(move || {
                for i in 0..500u16 {
                    port.transmit(&frame(0x100 + t, &i.to_le_bytes()));
                }
            })
        })
        .collect();
    for s in senders {
        s.join().unwrap();
    }
    let seen1: Vec<Frame> = std::iter::from_fn(|| rx1.try_recv()).collect();
    let seen2: Vec<Frame> = std::iter::from_fn(|| rx2.try_recv()).collect();
    assert_eq!(seen1.len(), 2000);
    assert_eq!(seen1, seen2);
    // Each sender's frames arrive in its own order.
    for t in 0..4u16 {
        let counts: Vec<u16> = seen1
            .iter()
            .filter(|f| f.standard_id() == Some(0x100 + t))
            .map(|f| u16::from_le_bytes([f.data()[0], f.data()[1]]))
            .collect();
        assert_eq!(counts, (0..500).collect::<Vec<_>>());
    }
}

#[test]
fn blocking_recv_across_threads() {
    let bus = VirtualBus::new();
    let mut a = bus.attach();
    let mut b = bus.attach();
    let echo = std::thread::spawn(move || {
        for _ in 0..100 {
            let f = b.recv(Duration::from_secs(5)).unwrap().unwrap();
            b.send(&frame(0x580, f.data())).unwrap();
        }
    });
    for i in 0..100u8 {
        a.send(&frame(0x600, &[i])).unwrap();
        let answer = a.recv(Duration::from_secs(5)).unwrap().unwrap();
        assert_eq!(answer, frame(0x580, &[i]));
    }
    echo.join().unwrap();
}

#[test]
fn ping_pong_throughput() {
    // Two ports, one thread: what a single-threaded client/server loop
    // pays per frame. Debug builds are slow; the bound is loose.
    let bus = VirtualBus::new();
    let client = bus.attach();
    let server = bus.attach();
    let request = frame(0x605, &[0x40, 0x17, 0x10, 0, 0, 0, 0, 0]);
    let response = frame(0x585, &[0x4B, 0x17, 0x10, 0, 0xE8, 0x03, 0, 0]);
    let rounds = 200_000u32;
    let start = std::time::Instant::now();
    for _ in 0..rounds {
        client.transmit(&request);
        let got = server.try_recv().unwrap();
        server.transmit(&response);
        let back = client.try_recv().unwrap();
        assert_eq!(got.len() + back.len(), 16);
    }
    let per_second = f64::from(2 * rounds) / start.elapsed().as_secs_f64();
    eprintln!("virtual bus: {per_second:.0} frames/s");
    assert!(per_second > 100_000.0, "{per_second}");
}

#[test]
fn candump_file_round_trip() {
    // Hand-written lines as candump -l writes them.
    let log = "(1700000000.000100) can0 000#8105\n\
               (1700000000.000350) can0 705#R\n\
               (1700000000.001000) can0 785#7F\n\
               (1700000000.002000) can0 605#4017100000000000\n\
               (1700000000.002400) can0 585#4B171000E8030000\n";
    let lines: Vec<LogLine> = Reader::new(log.as_bytes()).map(Result::unwrap).collect();
    assert_eq!(lines.len(), 5);
    assert_eq!(lines[0].frame, frame(0x000, &[0x81, 0x05]));
    assert_eq!(
        lines[1].frame,
        Frame::remote(CanId::Standard(0x705), 0).unwrap()
    );
    assert_eq!(
        lines[4].timestamp,
        Some(Duration::new(1_700_000_000, 2_400_000))
    );

    let path = std::env::temp_dir().join(format!("eds2rust-candump-{}.log", std::process::id()));
    let mut writer = Writer::new(std::fs::File::create(&path).unwrap(), Format::Log);
    for line in &lines {
        writer.write(line).unwrap();
    }
    writer.flush().unwrap();
    drop(writer);
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    assert_eq!(text, log);

    // The text form of the same lines, by hand.
    let mut writer = Writer::new(Vec::new(), Format::Text);
    writer.write(&lines[3]).unwrap();
    writer.write(&lines[1]).unwrap();
    assert_eq!(
        String::from_utf8(writer.into_inner()).unwrap(),
        "(1700000000.002000)  can0  605   [8]  40 17 10 00 00 00 00 00\n\
         (1700000000.000350)  can0  705   [0]  remote request\n"
    );
}
