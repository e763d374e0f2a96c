//! NMT and heartbeat interoperability with python-canopen 2.4.1, over the
//! `peer.py` bridge: our NMT master commanding python LocalNodes, python's
//! NMT commands parsed by our slave, and heartbeats both ways.
//!
//! python-canopen's NMT slave differs from CiA 301 in two ways the tests
//! record: a reset command received from the bus leaves it in INITIALISING
//! (no boot-up message, no move to PRE-OPERATIONAL), and its master reads a
//! boot-up message (state 0) as PRE-OPERATIONAL.

use std::sync::OnceLock;
use std::time::{Duration, Instant};

use eds2rust_drivers::linak_techline::od::{ProducerHeartbeatTime, ProducerHeartbeatTimeValue};
use eds2rust_runtime::blocking::SdoClient;
use eds2rust_runtime::heartbeat::{HeartbeatConsumer, HeartbeatEvent, HeartbeatProducer};
use eds2rust_runtime::nmt::{
    NmtCommand, NmtEvent, NmtMaster, NmtSlave, NmtSlaveEvent, NmtState, NmtTarget, parse_command,
};
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::sdo::Channel;
use eds2rust_runtime::sdo::client::ClientConfig;
use eds2rust_runtime::transport::{Bus, Clock};
use eds2rust_runtime::{Frame, Service};
use eds2rust_tests::peer::{self, PyPeer};
use serde_json::{Value, json};

static PEER: OnceLock<PyPeer> = OnceLock::new();

fn py() -> &'static PyPeer {
    peer::shared(&PEER)
}

fn node(id: u8) -> NodeId {
    NodeId::new(id).expect("a valid node id")
}

fn ok(peer: &PyPeer, command: Value) -> Value {
    peer.command_ok(command).unwrap_or_else(|e| panic!("{e}"))
}

/// A python LocalNode whose heartbeat producer time (0x1017) is `period_ms`.
fn python_node(peer: &PyPeer, id: u8, period_ms: u16) {
    let objects = json!([{"index": 0x1017, "type": "UNSIGNED16", "access": "rw",
                          "value": peer::hex(&period_ms.to_le_bytes())}]);
    ok(
        peer,
        json!({"op": "local_node", "node": id, "objects": objects}),
    );
}

/// The NMT state code of a python LocalNode, once it handled every frame
/// sent to it so far.
fn python_state(peer: &PyPeer, id: u8) -> u64 {
    peer.barrier().unwrap_or_else(|e| panic!("{e}"));
    let reply = ok(peer, json!({"op": "local_state", "node": id}));
    reply["code"].as_u64().expect("a state code")
}

fn send_all<S: Service>(bus: &mut impl Bus, service: &mut S) {
    peer::flush(bus, service).unwrap_or_else(|e| panic!("{e}"));
}

/// Steps `service` until `want` matches one of its events (10 s at most).
fn wait_event<S: Service>(
    peer: &PyPeer,
    bus: &mut impl Bus,
    clock: &Clock,
    service: &mut S,
    want: impl Fn(&S::Event) -> bool,
) -> S::Event
where
    S::Event: std::fmt::Debug,
{
    peer::run_until(bus, clock, service, Duration::from_secs(10), |e| {
        want(&e).then_some(e)
    })
    .unwrap_or_else(|e| panic!("{}", peer.failure(&e)))
}

#[test]
fn our_nmt_master_commands_python_node() {
    const ID: u8 = 0x30;
    let py = py();
    python_node(py, ID, 20);
    let mut port = py.port();
    let clock = Clock::new();
    let mut master = NmtMaster::new();
    let n = node(ID);

    // python's application boots the node: boot-up, then heartbeats.
    ok(
        py,
        json!({"op": "local_nmt", "node": ID, "state": "INITIALISING"}),
    );
    wait_event(py, &mut port, &clock, &mut master, |e| {
        *e == NmtEvent::BootUp(n)
    });
    ok(
        py,
        json!({"op": "local_nmt", "node": ID, "state": "PRE-OPERATIONAL"}),
    );
    wait_event(
        py,
        &mut port,
        &clock,
        &mut master,
        |e| matches!(e, NmtEvent::StateChanged { node, to: NmtState::PreOperational, .. } if *node == n),
    );

    for (cmd, code, state) in [
        (NmtCommand::Start, 5, NmtState::Operational),
        (NmtCommand::Stop, 4, NmtState::Stopped),
        (
            NmtCommand::EnterPreOperational,
            127,
            NmtState::PreOperational,
        ),
        (NmtCommand::Start, 5, NmtState::Operational),
    ] {
        // A command for another node first: python must ignore it.
        let other = if cmd == NmtCommand::Stop {
            NmtCommand::Start
        } else {
            NmtCommand::Stop
        };
        master.send(other, NmtTarget::Node(node(ID + 1))).unwrap();
        master.send(cmd, NmtTarget::Node(n)).unwrap();
        send_all(&mut port, &mut master);
        assert_eq!(python_state(py, ID), code, "after {cmd}");
        // python's heartbeat reports the new state to our master.
        wait_event(
            py,
            &mut port,
            &clock,
            &mut master,
            |e| matches!(e, NmtEvent::StateChanged { node, to, .. } if *node == n && *to == state),
        );
        assert_eq!(master.state(n), Some(state));
        assert_eq!(master.expected(n), Some(state));
    }

    // Resets: python-canopen's slave stays in INITIALISING (0).
    for cmd in [NmtCommand::ResetCommunication, NmtCommand::ResetNode] {
        ok(
            py,
            json!({"op": "local_nmt", "node": ID, "state": "OPERATIONAL"}),
        );
        master.send(cmd, NmtTarget::Node(n)).unwrap();
        send_all(&mut port, &mut master);
        assert_eq!(python_state(py, ID), 0, "after {cmd}");
    }
    ok(py, json!({"op": "heartbeat_stop", "node": ID}));
}

#[test]
fn our_nmt_broadcast_reaches_every_python_node() {
    // Its own peer: a broadcast would disturb the other tests' nodes.
    let py = PyPeer::spawn().unwrap_or_else(|e| panic!("{e}"));
    for id in [1, 2, 0x7F] {
        python_node(&py, id, 0);
    }
    let mut port = py.port();
    let mut master = NmtMaster::new();
    for (cmd, code) in [
        (NmtCommand::Start, 5),
        (NmtCommand::Stop, 4),
        (NmtCommand::EnterPreOperational, 127),
    ] {
        master.send(cmd, NmtTarget::All).unwrap();
        send_all(&mut port, &mut master);
        for id in [1, 2, 0x7F] {
            assert_eq!(
                python_state(&py, id),
                code,
                "node {id} after broadcast {cmd}"
            );
        }
    }
}

#[test]
fn python_nmt_commands_parse_with_our_slave() {
    const ID: u8 = 0x32;
    let py = py();
    let mut port = py.port();
    let mut slave = NmtSlave::new(node(ID));
    slave.boot_complete();
    assert_eq!(slave.state(), NmtState::PreOperational);
    while slave.poll_event().is_some() {}

    // Runs one python NMT command; returns the NMT frames it sent, after
    // feeding everything python sent to our slave.
    let mut run = |target: u8, command: u8, slave: &mut NmtSlave| -> Vec<Frame> {
        ok(
            py,
            json!({"op": "nmt_command", "node": target, "command": command}),
        );
        let frames = py.settle(&mut port).unwrap_or_else(|e| panic!("{e}"));
        let now = Clock::new().now();
        for frame in &frames {
            slave.handle_frame(now, frame);
        }
        frames
            .into_iter()
            .filter(|f| f.standard_id() == Some(0))
            .collect()
    };
    let events =
        |slave: &mut NmtSlave| std::iter::from_fn(|| slave.poll_event()).collect::<Vec<_>>();
    use NmtState::*;

    for (command, cmd, from, to) in [
        (0x01, NmtCommand::Start, PreOperational, Operational),
        (0x02, NmtCommand::Stop, Operational, Stopped),
        (
            0x80,
            NmtCommand::EnterPreOperational,
            Stopped,
            PreOperational,
        ),
    ] {
        let frames = run(ID, command, &mut slave);
        assert_eq!(frames.len(), 1, "{frames:?}");
        assert_eq!(frames[0].data(), &[command, ID]);
        assert_eq!(
            parse_command(&frames[0]),
            Some((cmd, NmtTarget::Node(node(ID))))
        );
        assert_eq!(
            events(&mut slave),
            vec![NmtSlaveEvent::StateChanged { from, to }]
        );
    }

    // Addressed to another node (one no test of this file uses): ignored.
    let frames = run(0x3F, 0x01, &mut slave);
    assert_eq!(
        parse_command(&frames[0]),
        Some((NmtCommand::Start, NmtTarget::Node(node(0x3F))))
    );
    assert_eq!(events(&mut slave), vec![]);

    // python's SLEEP and STANDBY are no CiA 301 commands: not parsed.
    for command in [80, 96] {
        let frames = run(ID, command, &mut slave);
        assert_eq!(frames[0].data(), &[command, ID]);
        assert_eq!(parse_command(&frames[0]), None);
        assert_eq!(events(&mut slave), vec![]);
    }

    // Broadcast from python's network NMT master (node 0).
    let frames = run(0, 0x01, &mut slave);
    assert_eq!(
        parse_command(&frames[0]),
        Some((NmtCommand::Start, NmtTarget::All))
    );
    assert_eq!(
        events(&mut slave),
        vec![NmtSlaveEvent::StateChanged {
            from: PreOperational,
            to: Operational
        }]
    );

    // Resets: reported, then the slave is back in boot-up (and boots again).
    for (code, command, reset, from) in [
        (
            0x82,
            NmtCommand::ResetCommunication,
            NmtSlaveEvent::ResetCommunication,
            Operational,
        ),
        (
            0x81,
            NmtCommand::ResetNode,
            NmtSlaveEvent::ResetNode,
            PreOperational,
        ),
    ] {
        let frames = run(ID, code, &mut slave);
        assert_eq!(
            parse_command(&frames[0]),
            Some((command, NmtTarget::Node(node(ID))))
        );
        let to = BootUp;
        assert_eq!(
            events(&mut slave),
            vec![reset, NmtSlaveEvent::StateChanged { from, to }]
        );
        slave.boot_complete();
        let _ = events(&mut slave);
    }
}

#[test]
fn python_heartbeat_reaches_our_consumer() {
    const ID: u8 = 0x33;
    let py = py();
    python_node(py, ID, 20);
    let n = node(ID);
    let clock = Clock::new();
    let mut port = py.port();
    let mut consumer = HeartbeatConsumer::new();
    consumer.monitor(n, Some(Duration::from_millis(150)));

    // Boot-up, then boot complete: python starts its heartbeat (0x1017 =
    // 20 ms) in pre-operational, then operational.
    for (python, state) in [
        ("INITIALISING", NmtState::BootUp),
        ("PRE-OPERATIONAL", NmtState::PreOperational),
        ("OPERATIONAL", NmtState::Operational),
    ] {
        ok(py, json!({"op": "local_nmt", "node": ID, "state": python}));
        wait_event(py, &mut port, &clock, &mut consumer, |e| {
            *e == HeartbeatEvent::State { node: n, state }
        });
    }
    assert_eq!(consumer.state(n), Some(NmtState::Operational));
    assert!(!consumer.is_timed_out(n));

    // Our SDO client sets python's producer time to 0: the heartbeat stops.
    write_heartbeat_time(py, ID, 0);
    let started = Instant::now();
    wait_event(py, &mut port, &clock, &mut consumer, |e| {
        *e == HeartbeatEvent::Timeout { node: n }
    });
    assert!(consumer.is_timed_out(n));
    assert!(
        started.elapsed() >= Duration::from_millis(100),
        "timed out too early"
    );

    // And back to 20 ms: it resumes in the state it was in.
    write_heartbeat_time(py, ID, 20);
    wait_event(py, &mut port, &clock, &mut consumer, |e| {
        *e == HeartbeatEvent::Resumed {
            node: n,
            state: NmtState::Operational,
        }
    });
    assert!(!consumer.is_timed_out(n));
    ok(py, json!({"op": "heartbeat_stop", "node": ID}));
}

/// Writes python LocalNode `id`'s 0x1017 with our blocking SDO client,
/// through the generated entry of the LINAK TECHLINE driver.
fn write_heartbeat_time(py: &PyPeer, id: u8, millis: u16) {
    let mut client = SdoClient::new(py.port(), ClientConfig::new(Channel::default_for(node(id))));
    client
        .write::<ProducerHeartbeatTime>(ProducerHeartbeatTimeValue(millis))
        .unwrap_or_else(|e| panic!("{}", py.failure(&format!("writing 0x1017: {e}"))));
}

/// A bus that keeps what is sent through it.
struct Recording<B> {
    bus: B,
    sent: Vec<Frame>,
}

impl<B: Bus> Bus for Recording<B> {
    fn send(&mut self, frame: &Frame) -> std::io::Result<()> {
        self.sent.push(*frame);
        self.bus.send(frame)
    }
    fn recv(&mut self, timeout: Duration) -> std::io::Result<Option<Frame>> {
        self.bus.recv(timeout)
    }
}

#[test]
fn our_heartbeat_reaches_python() {
    const ID: u8 = 0x34;
    let py = py();
    let n = node(ID);
    let clock = Clock::new();
    let mut bus = Recording {
        bus: py.port(),
        sent: Vec::new(),
    };
    let remote = |py: &PyPeer| {
        py.barrier().unwrap_or_else(|e| panic!("{e}"));
        ok(py, json!({"op": "remote_state", "node": ID}))
    };
    // python's RemoteNode exists before our node boots.
    assert_eq!(remote(py)["heard"], json!([]));

    let mut producer = HeartbeatProducer::new(n, Some(Duration::from_millis(20)));
    producer.start(clock.now());
    producer.set_state(NmtState::PreOperational);
    // Runs the producer until it sent `count` more frames.
    let beat = |producer: &mut HeartbeatProducer, bus: &mut Recording<_>, count: usize| {
        let target = bus.sent.len() + count;
        let deadline = Instant::now() + Duration::from_secs(5);
        while bus.sent.len() < target {
            assert!(
                Instant::now() < deadline,
                "our producer sent {:?}",
                bus.sent
            );
            peer::step(bus, &clock, producer, Duration::from_millis(50))
                .unwrap_or_else(|e| panic!("{e}"));
        }
    };
    beat(&mut producer, &mut bus, 3);
    let reply = remote(py);
    assert_eq!(reply["heard"], json!([0, 127, 127]), "{reply}");
    assert_eq!(reply["state"], "PRE-OPERATIONAL");
    for frame in &bus.sent {
        assert_eq!(frame.standard_id(), Some(0x700 + u16::from(ID)));
    }

    for (state, name, code) in [
        (NmtState::Operational, "OPERATIONAL", 5),
        (NmtState::Stopped, "STOPPED", 4),
    ] {
        producer.set_state(state);
        beat(&mut producer, &mut bus, 2);
        let reply = remote(py);
        assert_eq!(reply["state"], name, "{reply}");
        let heard = reply["heard"].as_array().expect("a list");
        assert_eq!(
            heard[heard.len() - 2..],
            [json!(code), json!(code)],
            "{reply}"
        );
    }

    // python's own wait: the next heartbeat gives our state.
    producer.set_state(NmtState::Operational);
    let id = py
        .start(json!({"op": "wait_heartbeat", "node": ID, "timeout": 5.0}))
        .unwrap_or_else(|e| panic!("{e}"));
    let deadline = Instant::now() + Duration::from_secs(10);
    let reply = loop {
        peer::step(&mut bus, &clock, &mut producer, Duration::from_millis(10))
            .unwrap_or_else(|e| panic!("{e}"));
        if let Some(reply) = py.try_reply(id).unwrap_or_else(|e| panic!("{e}")) {
            break reply;
        }
        assert!(
            Instant::now() < deadline,
            "{}",
            py.failure("no reply to wait_heartbeat")
        );
    };
    assert_eq!(reply["state"], "OPERATIONAL", "{reply}");
}
