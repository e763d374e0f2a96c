use std::collections::VecDeque;
use std::vec::Vec;

use super::*;

/// A device frame type: up to 8 bytes, or up to 64 ("FD") to test skipping.
#[derive(Debug, Clone, PartialEq, Eq)]
struct FakeFrame {
    id: Id,
    remote: bool,
    dlc: usize,
    data: Vec<u8>,
}

impl embedded_can::Frame for FakeFrame {
    fn new(id: impl Into<Id>, data: &[u8]) -> Option<Self> {
        (data.len() <= 64).then(|| FakeFrame {
            id: id.into(),
            remote: false,
            dlc: data.len(),
            data: data.to_vec(),
        })
    }
    fn new_remote(id: impl Into<Id>, dlc: usize) -> Option<Self> {
        (dlc <= 8).then(|| FakeFrame {
            id: id.into(),
            remote: true,
            dlc,
            data: Vec::new(),
        })
    }
    fn is_extended(&self) -> bool {
        matches!(self.id, Id::Extended(_))
    }
    fn is_remote_frame(&self) -> bool {
        self.remote
    }
    fn id(&self) -> Id {
        self.id
    }
    fn dlc(&self) -> usize {
        self.dlc
    }
    fn data(&self) -> &[u8] {
        &self.data
    }
}

/// A device with a receive queue, a transmit log and a transmit queue of
/// `room` slots that the test empties by hand.
#[derive(Debug, Default)]
struct FakeDevice {
    rx: VecDeque<Result<FakeFrame, embedded_can::ErrorKind>>,
    tx_queue: Vec<FakeFrame>,
    room: usize,
    sent: Vec<FakeFrame>,
}

impl embedded_can::blocking::Can for FakeDevice {
    type Frame = FakeFrame;
    type Error = embedded_can::ErrorKind;
    fn transmit(&mut self, frame: &FakeFrame) -> Result<(), Self::Error> {
        self.sent.push(frame.clone());
        Ok(())
    }
    fn receive(&mut self) -> Result<FakeFrame, Self::Error> {
        self.rx
            .pop_front()
            .unwrap_or(Err(embedded_can::ErrorKind::Other))
    }
}

fn raw_id(frame: &FakeFrame) -> u32 {
    match frame.id {
        Id::Standard(id) => u32::from(id.as_raw()),
        Id::Extended(id) => id.as_raw(),
    }
}

impl embedded_can::nb::Can for FakeDevice {
    type Frame = FakeFrame;
    type Error = embedded_can::ErrorKind;
    fn transmit(&mut self, frame: &FakeFrame) -> nb::Result<Option<FakeFrame>, Self::Error> {
        if self.tx_queue.len() < self.room {
            self.tx_queue.push(frame.clone());
            return Ok(None);
        }
        // Full: a lower-priority (higher id) queued frame makes room.
        let worst = (0..self.tx_queue.len()).max_by_key(|&i| raw_id(&self.tx_queue[i]));
        match worst {
            Some(i) if raw_id(&self.tx_queue[i]) > raw_id(frame) => Ok(Some(std::mem::replace(
                &mut self.tx_queue[i],
                frame.clone(),
            ))),
            _ => Err(nb::Error::WouldBlock),
        }
    }
    fn receive(&mut self) -> nb::Result<FakeFrame, Self::Error> {
        match self.rx.pop_front() {
            Some(Ok(frame)) => Ok(frame),
            Some(Err(e)) => Err(nb::Error::Other(e)),
            None => Err(nb::Error::WouldBlock),
        }
    }
}

fn fake(id: Id, data: &[u8]) -> FakeFrame {
    <FakeFrame as embedded_can::Frame>::new(id, data).unwrap()
}

fn std_id(raw: u16) -> Id {
    Id::Standard(StandardId::new(raw).unwrap())
}

#[test]
fn blocking_round_trip() {
    let mut bus = EmbeddedBus::new(FakeDevice::default());
    let heartbeat = Frame::new(CanId::Standard(0x701), &[0x05]).unwrap();
    let rtr = Frame::remote(CanId::Standard(0x701), 1).unwrap();
    let ext = Frame::new(CanId::Extended(0x1ABC_DEF0), &[1, 2, 3]).unwrap();
    for frame in [heartbeat, rtr, ext] {
        bus.send(&frame).unwrap();
    }
    let sent = &bus.device().sent;
    assert_eq!(sent[0], fake(std_id(0x701), &[0x05]));
    assert_eq!(
        sent[1],
        FakeFrame {
            id: std_id(0x701),
            remote: true,
            dlc: 1,
            data: Vec::new()
        }
    );
    assert_eq!(
        sent[2],
        fake(
            Id::Extended(ExtendedId::new(0x1ABC_DEF0).unwrap()),
            &[1, 2, 3]
        )
    );

    // What the device received comes back as our frames; an FD-sized frame
    // is skipped; a device error becomes an io::Error.
    let sent = bus.device().sent.clone();
    let rx = &mut bus.device().rx;
    rx.push_back(Ok(fake(std_id(0x123), &[0; 12])));
    rx.extend(sent.into_iter().map(Ok));
    rx.push_back(Err(embedded_can::ErrorKind::Overrun));
    assert_eq!(bus.recv(Duration::ZERO).unwrap(), Some(heartbeat));
    assert_eq!(bus.recv(Duration::ZERO).unwrap(), Some(rtr));
    assert_eq!(bus.recv(Duration::ZERO).unwrap(), Some(ext));
    let error = bus.recv(Duration::ZERO).unwrap_err();
    assert_eq!(error.kind(), io::ErrorKind::Other);
    let inner = error
        .get_ref()
        .and_then(|e| e.downcast_ref::<DeviceError>())
        .unwrap();
    assert_eq!(inner.kind, embedded_can::ErrorKind::Overrun);
}

#[test]
fn nb_recv_polls_until_timeout() {
    let mut bus =
        EmbeddedNbBus::new(FakeDevice::default()).with_poll_interval(Duration::from_millis(1));
    let start = std::time::Instant::now();
    assert_eq!(bus.recv(Duration::from_millis(20)).unwrap(), None);
    assert!(start.elapsed() >= Duration::from_millis(20));
    bus.device().rx.push_back(Ok(fake(std_id(0x181), &[1, 2])));
    assert_eq!(
        bus.recv(Duration::from_millis(20)).unwrap(),
        Some(Frame::new(CanId::Standard(0x181), &[1, 2]).unwrap())
    );
    bus.device().rx.push_back(Err(embedded_can::ErrorKind::Bit));
    assert!(bus.recv(Duration::from_millis(20)).is_err());
}

#[test]
fn nb_send_requeues_displaced_frames_and_times_out_when_full() {
    let mut bus = EmbeddedNbBus::new(FakeDevice {
        room: 2,
        ..FakeDevice::default()
    })
    .with_poll_interval(Duration::from_millis(1))
    .with_send_timeout(Duration::from_millis(20));
    bus.send(&Frame::new(CanId::Standard(0x300), &[3]).unwrap())
        .unwrap();
    bus.send(&Frame::new(CanId::Standard(0x200), &[2]).unwrap())
        .unwrap();
    // The queue is full; 0x100 displaces 0x300, which is queued again, finds
    // no room (nothing is lower than it) and times out.
    let error = bus
        .send(&Frame::new(CanId::Standard(0x100), &[1]).unwrap())
        .unwrap_err();
    assert_eq!(error.kind(), io::ErrorKind::TimedOut);
    // With room freed, a displaced frame goes back into the queue.
    bus.device().tx_queue.clear();
    bus.device().room = 2;
    bus.send(&Frame::new(CanId::Standard(0x500), &[5]).unwrap())
        .unwrap();
    bus.send(&Frame::new(CanId::Standard(0x400), &[4]).unwrap())
        .unwrap();
    bus.device().room = 3;
    bus.send(&Frame::new(CanId::Standard(0x050), &[0]).unwrap())
        .unwrap();
    let mut ids: Vec<u32> = bus.device().tx_queue.iter().map(raw_id).collect();
    ids.sort_unstable();
    assert_eq!(ids, [0x050, 0x400, 0x500]);
}

#[test]
fn id_conversion_round_trips() {
    for id in [
        CanId::Standard(0),
        CanId::Standard(0x7FF),
        CanId::Extended(0),
        CanId::Extended(0x1FFF_FFFF),
    ] {
        assert_eq!(from_embedded_id(to_embedded_id(id)), id);
    }
    assert_eq!(
        from_embedded_id(to_embedded_id(CanId::Standard(0xFFFF))),
        CanId::Standard(0x7FF)
    );
}
