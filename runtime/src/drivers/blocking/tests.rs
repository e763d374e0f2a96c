use std::sync::Arc;

use super::*;
use crate::od::NodeId;
use crate::sdo::{AbortCode, Channel, SdoError};
use crate::transport::ManualClock;
use crate::transport::virtual_bus::{VirtualBus, VirtualPort};
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
        if frame.standard_id() == Some(self.listen) {
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

/// A bus, a port on it, and a manual clock (its handle and a clock on it).
fn manual_rig() -> (VirtualBus, VirtualPort, ManualClock, Clock) {
    let bus = VirtualBus::new();
    let port = bus.attach();
    let time = ManualClock::new();
    let clock = time.clock();
    (bus, port, time, clock)
}

#[test]
fn run_sends_feeds_frames_and_stops_on_break() {
    let bus = VirtualBus::new();
    let mut port = bus.attach();
    let peer = bus.attach();
    peer.transmit(&frame(0x300, &[9]));
    peer.transmit(&frame(0x200, &[1]));
    let clock = Clock::new();
    let mut core = Pinger::new(Some(frame(0x100, &[7])), 0x200, Duration::from_secs(60));
    let got = run(
        &mut port,
        &clock,
        &mut core,
        // A deadline in the cores' own time.
        clock.now() + Duration::from_secs(5),
        |event| match event {
            PingEvent::Got(frame) => ControlFlow::Break(frame),
            PingEvent::Tick(_) => ControlFlow::Continue(()),
        },
    )
    .unwrap();
    assert_eq!(got, frame(0x200, &[1]));
    // The core's frame went out.
    assert_eq!(peer.try_recv(), Some(frame(0x100, &[7])));
}

#[test]
fn run_runs_timers_and_honours_the_deadline() {
    let (_bus, mut port, time, clock) = manual_rig();
    let mut core = Pinger::new(None, 0x200, Duration::from_millis(10));
    let mut ticks = Vec::new();
    let result = run(
        &mut port,
        &clock,
        &mut core,
        Instant::from_millis(60),
        |event| {
            if let PingEvent::Tick(at) = event {
                ticks.push(at);
            }
            ControlFlow::<()>::Continue(())
        },
    );
    assert!(matches!(result, Err(RunError::Deadline)));
    assert_eq!(time.now(), Instant::from_millis(60));
    // Each tick came exactly at its deadline; the one due at the deadline
    // itself did not run.
    let due: Vec<Instant> = (1..=5).map(|n| Instant::from_millis(10 * n)).collect();
    assert_eq!(ticks, due);
}

#[test]
fn a_manual_clock_takes_frames_already_there_and_never_waits() {
    let (bus, mut port, time, clock) = manual_rig();
    let peer = bus.attach();
    let mut core = Pinger::new(None, 0x200, Duration::from_secs(3600));
    peer.transmit(&frame(0x200, &[1]));
    let real = std::time::Instant::now();
    let mut seen = Vec::new();
    let result = run(
        &mut port,
        &clock,
        &mut core,
        Instant::from_millis(10_000),
        |event| {
            seen.push(event);
            ControlFlow::<()>::Continue(())
        },
    );
    assert!(matches!(result, Err(RunError::Deadline)));
    // The frame came at time zero; ten seconds passed on the clock only.
    assert_eq!(seen, [PingEvent::Got(frame(0x200, &[1]))]);
    assert_eq!(time.now(), Instant::from_millis(10_000));
    assert!(real.elapsed() < Duration::from_secs(5));
    // A frame sent later is taken at the clock's time then.
    time.advance(Duration::from_millis(5));
    peer.transmit(&frame(0x200, &[2]));
    let got = run(
        &mut port,
        &clock,
        &mut core,
        Deadline::NEVER,
        |event| match event {
            PingEvent::Got(frame) => ControlFlow::Break(frame),
            PingEvent::Tick(_) => ControlFlow::Continue(()),
        },
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
fn run_and_serve_take_deadlines_in_the_cores_time() {
    let (_bus, mut port, _time, clock) = manual_rig();
    let mut core = Pinger::new(None, 0x200, Duration::from_millis(10));
    let mut ticks = 0;
    let deadline = clock.now() + Duration::from_millis(35);
    let result = run(&mut port, &clock, &mut core, deadline, |event| {
        if let PingEvent::Tick(_) = event {
            ticks += 1;
        }
        ControlFlow::<()>::Continue(())
    });
    assert!(matches!(result, Err(RunError::Deadline)));
    assert_eq!(clock.now(), deadline);
    assert_eq!(ticks, 3);

    let stop = AtomicBool::new(false);
    let deadline = clock.now() + Duration::from_millis(20);
    serve(&mut port, &clock, &mut core, &stop, deadline, |_| {}).unwrap();
    assert_eq!(clock.now(), deadline);
    // Deadline::NEVER with the stop flag already set: returns at once.
    stop.store(true, Ordering::Relaxed);
    serve(&mut port, &clock, &mut core, &stop, Deadline::NEVER, |_| {}).unwrap();
    // A deadline already passed ends the run before it waits.
    let result = run(&mut port, &clock, &mut core, Instant::ZERO, |_| {
        ControlFlow::<()>::Continue(())
    });
    assert!(matches!(result, Err(RunError::Deadline)));
}

#[test]
fn visible_strings() {
    let object = Object::new(NodeId::new(5), 0x1008, 0);
    let text = |data: &[u8]| visible_string(data.to_vec(), object);
    assert_eq!(text(b"Drive 1").unwrap(), "Drive 1");
    assert_eq!(text(b"ab\0\0\xFF").unwrap(), "ab");
    assert_eq!(text(b"").unwrap(), "");
    assert!(matches!(
        text(b"caf\xE9"),
        Err(Error::NotVisible {
            index: 0x1008,
            offset: 3,
            byte: 0xE9,
            ..
        })
    ));
    assert!(matches!(
        text(b"a\nb"),
        Err(Error::NotVisible {
            offset: 1,
            byte: b'\n',
            ..
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
    let object = Object::new(NodeId::new(5), 0x1017, 0);
    let e = object.sdo(SdoError::RemoteAbort(AbortCode::ObjectDoesNotExist));
    assert!(e.to_string().contains("0x06020000"), "{e}");
    assert!(
        e.to_string()
            .starts_with("SDO transfer of 0x1017:0 with node 5: "),
        "{e}"
    );
    assert_eq!(
        Error::NotVisible {
            node: None,
            index: 0x1008,
            sub: 0,
            offset: 2,
            byte: 0x80
        }
        .to_string(),
        "0x1008:0 on the SDO server: byte 0x80 at offset 2 is not a visible character \
         (0x20 to 0x7E); read the raw bytes instead"
    );
    assert_eq!(RunError::Deadline.to_string(), "the deadline passed");
}

#[test]
fn a_transfer_past_its_limit_is_not_a_step_timeout() {
    let object = Object::new(NodeId::new(5), 0x1F50, 1);
    let mut core = client::SdoClient::new(ClientConfig::new(Channel::default_for(
        NodeId::new(5).unwrap(),
    )));
    let limit = Duration::from_secs(3);
    let e = give_up(&mut core, RunError::Deadline, object, Some(limit));
    assert!(
        matches!(e, Error::TransferTooLong { index: 0x1F50, sub: 1, limit: l, .. } if l == limit),
        "{e:?}"
    );
    assert!(
        e.to_string().contains("took longer than its limit of 3s"),
        "{e}"
    );
    // A step the server left unanswered is the core's timeout instead.
    let step = object.sdo(SdoError::Timeout);
    assert_eq!(step.sdo_error(), Some(SdoError::Timeout));
}

#[test]
fn a_default_channel_names_its_node() {
    let node = NodeId::new(0x22).unwrap();
    assert_eq!(channel_node(Channel::default_for(node)), Some(node));
    assert_eq!(channel_node(Channel::standard(0x622, 0x5A3)), None);
    assert_eq!(channel_node(Channel::standard(0x600, 0x580)), None);
}
