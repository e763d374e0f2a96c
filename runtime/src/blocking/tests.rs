use std::sync::Arc;

use super::*;
use crate::transport::ManualClock;
use crate::transport::virtual_bus::VirtualBus;
use crate::{CanId, Frame};

/// A test core: sends `ping` once, reports every frame with id `listen`,
/// and reports `Tick` every `period` (its timer).
struct Pinger {
    ping: Option<Frame>,
    listen: u16,
    period: Duration,
    next_tick: Option<Instant>,
    events: Vec<PingEvent>,
}

#[derive(Debug, PartialEq)]
enum PingEvent {
    Got(Frame),
    Tick(Instant),
}

impl Pinger {
    fn new(ping: Option<Frame>, listen: u16, period: Duration) -> Pinger {
        Pinger {
            ping,
            listen,
            period,
            next_tick: Some(Instant::ZERO + period),
            events: Vec::new(),
        }
    }
}

impl Service for Pinger {
    type Event = PingEvent;
    fn handle_frame(&mut self, _now: Instant, frame: &Frame) {
        if frame.cob_id() == Some(self.listen) {
            self.events.push(PingEvent::Got(*frame));
        }
    }
    fn handle_timeout(&mut self, now: Instant) {
        self.events.push(PingEvent::Tick(now));
        self.next_tick = Some(now + self.period);
    }
    fn poll_transmit(&mut self) -> Option<Frame> {
        self.ping.take()
    }
    fn poll_event(&mut self) -> Option<PingEvent> {
        (!self.events.is_empty()).then(|| self.events.remove(0))
    }
    fn poll_timeout(&self) -> Option<Instant> {
        self.next_tick
    }
}

fn frame(id: u16, data: &[u8]) -> Frame {
    Frame::new(CanId::Standard(id), data).unwrap()
}

#[test]
fn drive_sends_feeds_frames_and_stops_on_break() {
    let bus = VirtualBus::new();
    let mut port = bus.attach();
    let peer = bus.attach();
    peer.transmit(&frame(0x300, &[9]));
    peer.transmit(&frame(0x200, &[1]));
    let clock = Clock::new();
    let mut core = Pinger::new(Some(frame(0x100, &[7])), 0x200, Duration::from_secs(60));
    let got = drive(
        &mut port,
        &clock,
        &mut core,
        |event| match event {
            PingEvent::Got(frame) => ControlFlow::Break(frame),
            PingEvent::Tick(_) => ControlFlow::Continue(()),
        },
        // A deadline in the cores' own time.
        clock.now() + Duration::from_secs(5),
    )
    .unwrap();
    assert_eq!(got, frame(0x200, &[1]));
    // The core's frame went out.
    assert_eq!(peer.try_recv(), Some(frame(0x100, &[7])));
}

#[test]
fn drive_runs_timers_and_honours_the_deadline() {
    let bus = VirtualBus::new();
    let mut port = bus.attach();
    let time = ManualClock::new();
    let clock = time.clock();
    let mut core = Pinger::new(None, 0x200, Duration::from_millis(10));
    let mut ticks = Vec::new();
    let result = drive(
        &mut port,
        &clock,
        &mut core,
        |event| {
            if let PingEvent::Tick(at) = event {
                ticks.push(at);
            }
            ControlFlow::<()>::Continue(())
        },
        Instant::from_millis(60),
    );
    assert!(matches!(result, Err(DriveError::Deadline)));
    assert_eq!(time.now(), Instant::from_millis(60));
    // Each tick came exactly at its deadline; the one due at the deadline
    // itself did not run.
    let due: Vec<Instant> = (1..=5).map(|n| Instant::from_millis(10 * n)).collect();
    assert_eq!(ticks, due);
}

#[test]
fn a_manual_clock_takes_frames_already_there_and_never_waits() {
    let bus = VirtualBus::new();
    let mut port = bus.attach();
    let peer = bus.attach();
    let time = ManualClock::new();
    let clock = time.clock();
    let mut core = Pinger::new(None, 0x200, Duration::from_secs(3600));
    peer.transmit(&frame(0x200, &[1]));
    let real = std::time::Instant::now();
    let mut seen = Vec::new();
    let result = drive(
        &mut port,
        &clock,
        &mut core,
        |event| {
            seen.push(event);
            ControlFlow::<()>::Continue(())
        },
        Instant::from_millis(10_000),
    );
    assert!(matches!(result, Err(DriveError::Deadline)));
    // The frame came at time zero; ten seconds passed on the clock only.
    assert_eq!(seen, [PingEvent::Got(frame(0x200, &[1]))]);
    assert_eq!(time.now(), Instant::from_millis(10_000));
    assert!(real.elapsed() < Duration::from_secs(5));
    // A frame sent later is taken at the clock's time then.
    time.advance(Duration::from_millis(5));
    peer.transmit(&frame(0x200, &[2]));
    let got = drive(
        &mut port,
        &clock,
        &mut core,
        |event| match event {
            PingEvent::Got(frame) => ControlFlow::Break(frame),
            PingEvent::Tick(_) => ControlFlow::Continue(()),
        },
        Deadline::NEVER,
    );
    assert_eq!(got.unwrap(), frame(0x200, &[2]));
    assert_eq!(time.now(), Instant::from_millis(10_005));
}

#[test]
fn serve_stops_on_the_flag() {
    let bus = VirtualBus::new();
    let mut port = bus.attach();
    let peer = bus.attach();
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    let (seen, events) = std::sync::mpsc::channel();
    let server = std::thread::spawn(move || {
        let clock = Clock::new();
        let mut core = Pinger::new(None, 0x200, Duration::from_secs(60));
        serve(&mut port, &clock, &mut core, &flag, None, |e| {
            seen.send(e).unwrap();
        })
        .unwrap();
    });
    peer.transmit(&frame(0x200, &[1]));
    peer.transmit(&frame(0x201, &[2]));
    peer.transmit(&frame(0x200, &[3]));
    // Frames arrive in send order, so 0x201 was handled (and not
    // reported) before the last event came.
    let wait = Duration::from_secs(5);
    assert_eq!(
        events.recv_timeout(wait).unwrap(),
        PingEvent::Got(frame(0x200, &[1]))
    );
    assert_eq!(
        events.recv_timeout(wait).unwrap(),
        PingEvent::Got(frame(0x200, &[3]))
    );
    stop.store(true, Ordering::Relaxed);
    server.join().unwrap();
    assert_eq!(
        events.try_recv(),
        Err(std::sync::mpsc::TryRecvError::Disconnected)
    );
}

#[test]
fn serve_ends_at_its_deadline() {
    let bus = VirtualBus::new();
    let mut port = bus.attach();
    let stop = AtomicBool::new(false);
    let clock = Clock::new();
    let mut core = Pinger::new(None, 0x200, Duration::from_secs(60));
    let start = std::time::Instant::now();
    let deadline = start + Duration::from_millis(30);
    serve(&mut port, &clock, &mut core, &stop, Some(deadline), |_| {}).unwrap();
    let took = start.elapsed();
    assert!(took >= Duration::from_millis(30) && took < Duration::from_secs(2));
}

#[test]
fn drive_and_serve_take_deadlines_in_the_cores_time() {
    let bus = VirtualBus::new();
    let mut port = bus.attach();
    let time = ManualClock::new();
    let clock = time.clock();
    let mut core = Pinger::new(None, 0x200, Duration::from_millis(10));
    let mut ticks = 0;
    let deadline = clock.now() + Duration::from_millis(35);
    let result = drive(
        &mut port,
        &clock,
        &mut core,
        |event| {
            if let PingEvent::Tick(_) = event {
                ticks += 1;
            }
            ControlFlow::<()>::Continue(())
        },
        deadline,
    );
    assert!(matches!(result, Err(DriveError::Deadline)));
    assert_eq!(clock.now(), deadline);
    assert_eq!(ticks, 3);

    let stop = AtomicBool::new(false);
    let deadline = clock.now() + Duration::from_millis(20);
    serve(&mut port, &clock, &mut core, &stop, deadline, |_| {}).unwrap();
    assert_eq!(clock.now(), deadline);
    // Deadline::NEVER with the stop flag already set: returns at once.
    stop.store(true, Ordering::Relaxed);
    serve(&mut port, &clock, &mut core, &stop, Deadline::NEVER, |_| {}).unwrap();
    // A deadline already passed ends the drive before it waits.
    let result = drive(
        &mut port,
        &clock,
        &mut core,
        |_| ControlFlow::<()>::Continue(()),
        Instant::ZERO,
    );
    assert!(matches!(result, Err(DriveError::Deadline)));
}

#[test]
fn visible_strings() {
    assert_eq!(visible_string(b"Drive 1".to_vec()).unwrap(), "Drive 1");
    assert_eq!(visible_string(b"ab\0\0\xFF".to_vec()).unwrap(), "ab");
    assert_eq!(visible_string(Vec::new()).unwrap(), "");
    assert!(matches!(
        visible_string(b"caf\xE9".to_vec()),
        Err(Error::NotVisible {
            offset: 3,
            byte: 0xE9
        })
    ));
    assert!(matches!(
        visible_string(b"a\nb".to_vec()),
        Err(Error::NotVisible {
            offset: 1,
            byte: b'\n'
        })
    ));
}

#[test]
fn transfer_bound_counts_steps() {
    let mut config = ClientConfig::new(crate::sdo::Channel::standard(0x601, 0x581));
    config.timeout = Duration::from_millis(100);
    config.max_upload = 70;
    // 70 bytes: 10 segments + 4 = 14 steps.
    assert_eq!(
        Transfer::Upload(Method::Auto).bound(&config),
        Duration::from_millis(1400)
    );
    assert_eq!(
        Transfer::Download(&[0; 4], Method::Auto).bound(&config),
        Duration::from_millis(500)
    );
}

#[test]
fn errors_display() {
    let e = Error::Sdo(SdoError::RemoteAbort(AbortCode::ObjectDoesNotExist));
    assert!(e.to_string().contains("0x06020000"), "{e}");
    assert_eq!(
        Error::NotVisible {
            offset: 2,
            byte: 0x80
        }
        .to_string(),
        "byte 0x80 at offset 2 is not a visible character (0x20 to 0x7E)"
    );
    assert_eq!(DriveError::Deadline.to_string(), "the deadline passed");
}
