use std::string::{String, ToString};
use std::vec;

use super::*;
use crate::emcy::Emcy;
use crate::lss::LssState;
use crate::nmt::{NmtCommand, NmtState, NmtTarget};
use crate::sdo::SdoError;
use crate::{CanId, Frame};

fn node(id: u8) -> NodeId {
    NodeId::new(id).unwrap()
}

fn frame(id: u16, data: &[u8]) -> Frame {
    Frame::new(CanId::Standard(id), data).unwrap()
}

fn ms(n: u64) -> Instant {
    Instant::from_millis(n)
}

fn drain_frames(master: &mut Master) -> Vec<String> {
    core::iter::from_fn(|| master.poll_transmit())
        .map(|f| f.to_string())
        .collect()
}

fn drain_events(master: &mut Master) -> Vec<MasterEvent> {
    core::iter::from_fn(|| master.poll_event()).collect()
}

#[test]
fn frames_come_from_the_cores_in_turn_each_in_its_own_order() {
    let mut m = Master::new(node(1), Some(Duration::from_millis(100)));
    m.add_sdo_client(node(5), ClientConfig::new(Channel::default_for(node(5))));
    m.start(ms(0));
    m.nmt
        .send(NmtCommand::ResetCommunication, NmtTarget::All)
        .unwrap();
    m.nmt
        .send(NmtCommand::Start, NmtTarget::Node(node(5)))
        .unwrap();
    m.nmt
        .send(NmtCommand::Stop, NmtTarget::Node(node(6)))
        .unwrap();
    m.lss.switch_global(ms(0), LssState::Configuration).unwrap();
    m.sdo(node(5)).unwrap().upload(ms(0), 0x1018, 1).unwrap();
    assert_eq!(
        drain_frames(&mut m),
        [
            // One frame per core per round: NMT, heartbeat, LSS, SDO ...
            "000#8200",
            "701#00",
            "7E5#0401000000000000",
            "605#4018100100000000",
            // ... then the rest of the NMT queue in its order.
            "000#0105",
            "000#0206",
        ]
    );
    // The LSS request without answer ends once sent.
    assert_eq!(
        drain_events(&mut m),
        [MasterEvent::Lss(crate::lss::LssEvent::Sent)]
    );
}

#[test]
fn own_sync_drives_the_synchronous_rpdos_and_is_reported_on_request() {
    let mut m = Master::new(node(1), None);
    m.sync = Some(SyncProducer::new(Some(Duration::from_millis(10)), Some(2)).unwrap());
    // RPDO1 of node 5, synchronous cyclic every SYNC.
    let i = m
        .add_pdo_tx(TransmitterConfig::new(
            PdoCobId(0x205),
            TransmissionType::SynchronousCyclic(1),
        ))
        .unwrap();
    m.set_sync_events(true);
    m.start(ms(0));
    assert_eq!(drain_frames(&mut m), ["701#00"]);
    m.pdo_tx[i].set_data(ms(1), &[0x0F, 0x00]).unwrap();
    assert_eq!(m.poll_timeout(), Some(ms(10)));
    m.handle_timeout(ms(10));
    // CiA 301: the counter starts at 1; the PDO follows its SYNC.
    assert_eq!(drain_frames(&mut m), ["080#01", "205#0F00"]);
    m.handle_timeout(ms(20));
    assert_eq!(drain_frames(&mut m), ["080#02", "205#0F00"]);
    assert_eq!(
        drain_events(&mut m),
        [MasterEvent::Sync(Some(1)), MasterEvent::Sync(Some(2))]
    );
    m.set_sync_events(false);
    m.handle_timeout(ms(30));
    assert_eq!(drain_frames(&mut m), ["080#01", "205#0F00"]);
    assert_eq!(drain_events(&mut m), []);
}

#[test]
fn the_deadline_is_the_earliest_of_all_cores_and_only_due_cores_run() {
    let mut m = Master::new(node(1), Some(Duration::from_millis(100)));
    m.sync = Some(SyncProducer::new(Some(Duration::from_millis(30)), None).unwrap());
    let mut config = ClientConfig::new(Channel::default_for(node(5)));
    config.timeout = Duration::from_millis(50);
    m.add_sdo_client(node(5), config);
    assert_eq!(m.poll_timeout(), None);
    m.start(ms(0));
    assert_eq!(m.poll_timeout(), Some(ms(30)));
    m.sdo(node(5)).unwrap().upload(ms(0), 0x1000, 0).unwrap();
    drain_frames(&mut m);
    m.handle_timeout(ms(30));
    assert_eq!(drain_frames(&mut m), ["080#"]);
    assert_eq!(m.poll_timeout(), Some(ms(50)));
    // The SDO server never answers: abort 0x05040000 (timeout), and the
    // heartbeat is not due yet.
    m.handle_timeout(ms(50));
    assert_eq!(drain_frames(&mut m), ["605#8000100000000405"]);
    assert_eq!(
        drain_events(&mut m),
        [MasterEvent::Sdo(
            node(5),
            ClientEvent::Failed {
                index: 0x1000,
                sub: 0,
                error: SdoError::Timeout
            }
        )]
    );
    assert_eq!(m.poll_timeout(), Some(ms(60)));
    m.handle_timeout(ms(100));
    // The rotation goes on after the SDO client: heartbeat, then SYNC.
    assert_eq!(drain_frames(&mut m), ["701#7F", "080#"]);
}

#[test]
fn every_core_sees_every_frame() {
    let mut m = Master::new(node(1), None);
    m.consumer
        .monitor(node(5), Some(Duration::from_millis(500)));
    m.pdo_rx.watch(PdoCobId(0x185), 2, None).unwrap();
    m.add_sdo_client(node(5), ClientConfig::new(Channel::default_for(node(5))));
    m.start(ms(0));
    drain_frames(&mut m);
    m.sdo(node(5)).unwrap().upload(ms(0), 0x1017, 0).unwrap();
    assert_eq!(drain_frames(&mut m), ["605#4017100000000000"]);

    // Heartbeat of node 5, Operational.
    m.handle_frame(ms(1), &frame(0x705, &[0x05]));
    // TPDO1 of node 5.
    m.handle_frame(ms(2), &frame(0x185, &[0x37, 0x02]));
    // EMCY of node 5: 0x3210 (DC link over-voltage), error register 0x05.
    m.handle_frame(ms(3), &frame(0x085, &[0x10, 0x32, 0x05, 0, 0, 0, 0, 0]));
    // SDO answer: 0x1017:00 = 1000 (expedited, 2 bytes).
    m.handle_frame(
        ms(4),
        &frame(0x585, &[0x4B, 0x17, 0x10, 0x00, 0xE8, 0x03, 0, 0]),
    );

    let to = NmtState::Operational;
    assert_eq!(
        drain_events(&mut m),
        [
            MasterEvent::Nmt(NmtEvent::StateChanged {
                node: node(5),
                from: None,
                to
            }),
            MasterEvent::Heartbeat(HeartbeatEvent::State {
                node: node(5),
                state: to
            }),
            MasterEvent::Emcy(EmcyEvent::Emergency {
                node: node(5),
                emcy: Emcy::parse(&[0x10, 0x32, 0x05, 0, 0, 0, 0, 0]).unwrap()
            }),
            MasterEvent::Pdo(PdoEvent::Received {
                can_id: CanId::Standard(0x185),
                data: [0x37, 0x02, 0, 0, 0, 0, 0, 0],
                len: 2,
                at: ms(2)
            }),
            MasterEvent::Sdo(
                node(5),
                ClientEvent::Uploaded {
                    index: 0x1017,
                    sub: 0,
                    data: vec![0xE8, 0x03],
                    padded: false
                }
            ),
        ]
    );
    assert_eq!(m.nmt.state(node(5)), Some(to));
    assert_eq!(
        m.pdo_rx.latest_data(CanId::Standard(0x185)),
        Some(&[0x37, 0x02][..])
    );
}

#[test]
fn sdo_clients_are_kept_per_node() {
    let mut m = Master::new(node(1), None);
    assert!(m.sdo(node(7)).is_none());
    assert_eq!(
        m.sdo_or_default(node(7)).config().channel,
        Channel::standard(0x607, 0x587)
    );
    let custom = Channel::standard(0x640, 0x5C0);
    m.add_sdo_client(node(7), ClientConfig::new(custom));
    m.add_sdo_client(node(3), ClientConfig::new(Channel::default_for(node(3))));
    assert_eq!(m.sdo(node(7)).unwrap().config().channel, custom);
    assert_eq!(m.sdo_nodes().collect::<Vec<_>>(), [node(3), node(7)]);
    assert!(m.remove_sdo_client(node(3)).is_some());
    assert_eq!(m.sdo_nodes().collect::<Vec<_>>(), [node(7)]);
    assert_eq!(m.node(), node(1));
}

#[test]
fn time_frames_become_events_and_the_master_can_produce_time() {
    use crate::time_stamp::{DateTime, TimeError, TimeEvent, TimeOfDay, TimeProducer};
    let mut m = Master::new(node(1), None);
    m.start(ms(0));
    drain_frames(&mut m);
    // 2026-12-02T12:34:56.789Z: 45_296_789 ms = 0x02B3_2C95, day 15_676 =
    // 0x3D3C (the hand-worked frame of time_stamp::tests).
    m.handle_frame(ms(1), &frame(0x100, &[0x95, 0x2C, 0xB3, 0x02, 0x3C, 0x3D]));
    // Between the EMCY and the PDO events.
    m.handle_frame(ms(2), &frame(0x085, &[0x10, 0x32, 0x05, 0, 0, 0, 0, 0]));
    // Too short, and reserved bits set: events naming the frame.
    m.handle_frame(ms(3), &frame(0x100, &[0x95, 0x2C, 0xB3]));
    m.handle_frame(ms(4), &frame(0x100, &[0, 0, 0, 0x80, 0, 0]));
    let time = TimeOfDay::from_civil(DateTime::new(2026, 12, 2, 12, 34, 56, 789)).unwrap();
    assert_eq!(
        drain_events(&mut m),
        [
            MasterEvent::Emcy(EmcyEvent::Emergency {
                node: node(5),
                emcy: Emcy::parse(&[0x10, 0x32, 0x05, 0, 0, 0, 0, 0]).unwrap()
            }),
            MasterEvent::Time(TimeEvent::Time {
                time,
                received: ms(1)
            }),
            MasterEvent::Time(TimeEvent::Malformed {
                frame: frame(0x100, &[0x95, 0x2C, 0xB3]),
                error: TimeError::Length(3)
            }),
            MasterEvent::Time(TimeEvent::Malformed {
                frame: frame(0x100, &[0, 0, 0, 0x80, 0, 0]),
                error: TimeError::ReservedBits(8)
            }),
        ]
    );
    assert_eq!(m.time_rx.as_ref().unwrap().last(), Some((ms(1), time)));
    // Without a consumer TIME frames are ignored.
    m.time_rx = None;
    m.handle_frame(ms(5), &frame(0x100, &[0; 6]));
    assert_eq!(drain_events(&mut m), []);

    // A TIME producer every second, from the start.
    let mut m = Master::new(node(1), None);
    let mut producer = TimeProducer::new(Some(Duration::from_secs(1)));
    producer.set_time(ms(0), time);
    m.time_tx = Some(producer);
    m.start(ms(0));
    assert_eq!(m.poll_timeout(), Some(ms(0)));
    m.handle_timeout(ms(0));
    assert_eq!(drain_frames(&mut m), ["701#00", "100#952CB3023C3D"]);
    assert_eq!(m.poll_timeout(), Some(ms(1000)));
    m.handle_timeout(ms(1000));
    // 45_297_789 ms = 0x02B3_307D.
    assert_eq!(drain_frames(&mut m), ["100#7D30B3023C3D"]);
}

#[test]
fn a_plan_with_more_pdos_than_the_master_receives_says_so() {
    use crate::boot::{MasterPlan, NetworkPlan, PdoLink};
    use alloc::borrow::Cow;
    let links: Vec<PdoLink> = (0..=PDO_RX_SLOTS as u16)
        .map(|i| PdoLink {
            node: node(2),
            number: i + 1,
            cob_id: 0x100 + u32::from(i),
            transmission: 1,
            len: 2,
            event_timer: 0,
            inhibit_time: 0,
        })
        .collect();
    let plan = NetworkPlan {
        master: MasterPlan {
            node: node(1),
            heartbeat: None,
            sync_period: None,
            sync_overflow: 0,
        },
        slaves: Cow::Borrowed(&[]),
        boot_time: None,
        response_time: NetworkPlan::DEFAULT_RESPONSE_TIME,
        start_nodes: true,
        start_all_nodes: false,
        start_master: true,
        reset_all_nodes: false,
        stop_all_nodes: false,
        receive: Cow::Owned(links),
        transmit: Cow::Borrowed(&[]),
    };
    let error = Master::for_network(&plan).unwrap_err();
    assert_eq!(
        error.to_string(),
        "node 2 TPDO 513: the master cannot receive it: every PDO receiver slot is taken \
         (the master receives at most 512 PDOs; disable the TPDOs it does not need in the \
         bus file)"
    );
}
