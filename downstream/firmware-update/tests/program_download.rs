//! A 1 MiB program download to the simulated bootloader slave (the corpus
//! DCF's own object table, with the CiA 302-3 program model) on the
//! in-process virtual bus: streamed by block download from a reader that
//! makes the image as it is read, with progress reports, and confirmed by
//! the device's 0x1F56.

use std::io::{self, Read};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use eds2rust_runtime::blocking::{self, SdoClient};
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::sdo::Channel;
use eds2rust_runtime::sdo::client::{ClientConfig, WINDOW};
use eds2rust_runtime::transport::Clock;
use eds2rust_runtime::transport::virtual_bus::VirtualBus;
use eds2rust_sim::program::{ProgramControl, ProgramEvent};
use eds2rust_sim::{Device, DeviceConfig, SimEvent};
use firmware_update::{slave, update_program};

const IMAGE: usize = 1 << 20;

/// An image made as it is read: byte i is a hash of i.
struct Image {
    at: usize,
}

fn byte(i: usize) -> u8 {
    (i.wrapping_mul(2_654_435_761) >> 13) as u8
}

impl Read for Image {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = buf.len().min(IMAGE - self.at);
        for (k, slot) in buf[..n].iter_mut().enumerate() {
            *slot = byte(self.at + k);
        }
        self.at += n;
        Ok(n)
    }
}

#[test]
fn a_mebibyte_program_is_streamed_confirmed_and_started() {
    let node = NodeId::new(2).unwrap();
    let bus = VirtualBus::new();
    let mut port = bus.attach();
    let clock = Clock::new();
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    let device_clock = clock.clone();
    let served = std::thread::spawn(move || {
        let mut device = Device::new(
            slave::od::OBJECTS,
            DeviceConfig::node(node),
            ProgramControl,
            device_clock.now(),
        );
        device.set_max_variable_size(IMAGE);
        let mut events = Vec::new();
        blocking::serve(&mut port, &device_clock, &mut device, &flag, None, |e| {
            events.push(e)
        })
        .unwrap();
        (device, events)
    });

    let mut sdo = SdoClient::with_clock(
        bus.attach(),
        ClientConfig::new(Channel::default_for(node)),
        clock,
    );
    let mut reports = Vec::new();
    let crc = update_program(&mut sdo, Image { at: 0 }, IMAGE as u64, |p| reports.push(p))
        .unwrap_or_else(|e| panic!("{e}"));
    // The client held a window of the image, never the image.
    assert!(
        sdo.core().buffer_capacity() <= 2 * WINDOW,
        "{} bytes held",
        sdo.core().buffer_capacity()
    );
    stop.store(true, Ordering::Relaxed);
    let (device, events) = served.join().unwrap();

    // Progress: rising, sized, to the end.
    assert!(reports.len() > 100, "{} reports", reports.len());
    assert!(reports.windows(2).all(|w| w[0].done <= w[1].done));
    assert!(reports.iter().all(|p| p.total == Some(IMAGE)));
    assert_eq!(reports.last().map(|p| p.done), Some(IMAGE));

    // The device has the image, byte for byte, and runs it.
    let stored = device.table().get(0x1F50, 1).unwrap();
    assert_eq!(stored.len(), IMAGE);
    assert!(stored.iter().enumerate().all(|(i, b)| *b == byte(i)));
    let programs: Vec<&ProgramEvent> = events
        .iter()
        .filter_map(|e| match e {
            SimEvent::Model(p) => Some(p),
            _ => None,
        })
        .collect();
    assert_eq!(
        programs,
        [
            &ProgramEvent::Stopped { program: 1 },
            &ProgramEvent::Cleared { program: 1 },
            &ProgramEvent::Received {
                program: 1,
                len: IMAGE,
                crc32: crc
            },
            &ProgramEvent::Started { program: 1 },
        ]
    );
}
