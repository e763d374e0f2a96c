use super::*;
use crate::od::{NodeId, PdoLengthError};
use std::collections::BTreeMap;

/// (action, index, sub, bytes) of every step.
fn plan(config: &PdoConfig<'_>) -> Vec<(StepAction, u16, u8, Vec<u8>)> {
    config
        .steps()
        .map(|s| (s.action(), s.index(), s.sub(), s.bytes().to_vec()))
        .collect()
}

const STATUS_AND_POSITION: [u32; 2] = [0x6041_0010, 0x6064_0020];

/// TPDO1 of node 5: status word and position actual value, event-driven,
/// inhibit 10 ms, event timer 500 ms.
fn tpdo1() -> PdoConfig<'static> {
    PdoConfig::new(PdoDirection::Tpdo, 1, PdoCobId(0x185), &STATUS_AND_POSITION)
        .unwrap()
        .with_transmission_type(TransmissionType::from_raw(254))
        .with_inhibit_time(InhibitTime(100))
        .with_event_timer(EventTimer(500))
}

#[test]
fn two_entry_mapping_follows_the_cia_301_order() {
    use StepAction::{ReadBack, Write};
    let config = tpdo1();
    assert_eq!(config.check(), Ok(()));
    // Written from CiA 301 7.5.2.35/36 and the PDO mapping procedure:
    // invalidate, switch the mapping off, write entries, switch it on with
    // the count, communication parameters, validate. Values little-endian.
    let expected: Vec<(StepAction, u16, u8, Vec<u8>)> = vec![
        (Write, 0x1800, 1, vec![0x85, 0x01, 0x00, 0x80]),
        (Write, 0x1A00, 0, vec![0x00]),
        (Write, 0x1A00, 1, vec![0x10, 0x00, 0x41, 0x60]),
        (Write, 0x1A00, 2, vec![0x20, 0x00, 0x64, 0x60]),
        (Write, 0x1A00, 0, vec![0x02]),
        (Write, 0x1800, 2, vec![0xFE]),
        (Write, 0x1800, 3, vec![0x64, 0x00]),
        (Write, 0x1800, 5, vec![0xF4, 0x01]),
        (Write, 0x1800, 1, vec![0x85, 0x01, 0x00, 0x00]),
        (ReadBack, 0x1A00, 0, vec![0x02]),
        (ReadBack, 0x1A00, 1, vec![0x10, 0x00, 0x41, 0x60]),
        (ReadBack, 0x1A00, 2, vec![0x20, 0x00, 0x64, 0x60]),
        (ReadBack, 0x1800, 2, vec![0xFE]),
        (ReadBack, 0x1800, 3, vec![0x64, 0x00]),
        (ReadBack, 0x1800, 5, vec![0xF4, 0x01]),
        (ReadBack, 0x1800, 1, vec![0x85, 0x01, 0x00, 0x00]),
    ];
    assert_eq!(plan(&config), expected);
    assert_eq!(config.steps().len(), 16);
    assert_eq!(config.step_count(), 16);
    assert_eq!(config.step(16), None);
}

#[test]
fn only_given_parameters_are_written() {
    use StepAction::{ReadBack, Write};
    let entries = [0x6040_0010];
    let config = PdoConfig::new(PdoDirection::Rpdo, 2, PdoCobId(0x305), &entries)
        .unwrap()
        .with_sync_start(0);
    assert_eq!(
        (config.communication_index, config.mapping_index),
        (0x1401, 0x1601)
    );
    let expected: Vec<(StepAction, u16, u8, Vec<u8>)> = vec![
        (Write, 0x1401, 1, vec![0x05, 0x03, 0x00, 0x80]),
        (Write, 0x1601, 0, vec![0x00]),
        (Write, 0x1601, 1, vec![0x10, 0x00, 0x40, 0x60]),
        (Write, 0x1601, 0, vec![0x01]),
        (Write, 0x1401, 6, vec![0x00]),
        (Write, 0x1401, 1, vec![0x05, 0x03, 0x00, 0x00]),
        (ReadBack, 0x1601, 0, vec![0x01]),
        (ReadBack, 0x1601, 1, vec![0x10, 0x00, 0x40, 0x60]),
        (ReadBack, 0x1401, 6, vec![0x00]),
        (ReadBack, 0x1401, 1, vec![0x05, 0x03, 0x00, 0x00]),
    ];
    assert_eq!(plan(&config), expected);
    // An empty mapping: off, count 0, COB-ID.
    let empty = PdoConfig::new(PdoDirection::Tpdo, 512, PdoCobId(0x8000_0000), &[]).unwrap();
    assert_eq!(
        (empty.communication_index, empty.mapping_index),
        (0x19FF, 0x1BFF)
    );
    assert_eq!(plan(&empty).len(), 6);
    assert!(PdoConfig::new(PdoDirection::Tpdo, 0, PdoCobId(0x185), &[]).is_none());
    assert!(PdoConfig::new(PdoDirection::Tpdo, 513, PdoCobId(0x185), &[]).is_none());
}

#[test]
fn step_descriptions_name_object_and_value() {
    let steps: Vec<String> = tpdo1().steps().map(|s| s.to_string()).collect();
    assert_eq!(
        steps[0],
        "write COB-ID of 0x1800 = 0x80000185, disabling the PDO (object 0x1800 sub 1)"
    );
    assert_eq!(
        steps[1],
        "write number of mapped objects of 0x1A00 = 0, switching the mapping off (object 0x1A00 sub 0)"
    );
    assert_eq!(
        steps[3],
        "write mapping entry 2 of 0x1A00 = 0x60640020 (object 0x1A00 sub 2)"
    );
    assert_eq!(
        steps[6],
        "write inhibit time of 0x1800 = 100 (x 100 µs) (object 0x1800 sub 3)"
    );
    assert_eq!(
        steps[7],
        "write event timer of 0x1800 = 500 ms (object 0x1800 sub 5)"
    );
    assert_eq!(
        steps[8],
        "write COB-ID of 0x1800 = 0x00000185, enabling the PDO (object 0x1800 sub 1)"
    );
    assert_eq!(
        steps[10],
        "read back mapping entry 1 of 0x1A00, expecting 0x60410010 (object 0x1A00 sub 1)"
    );
}

#[test]
fn read_back_comparison() {
    let steps: Vec<Step> = tpdo1().steps().collect();
    let count = steps[9];
    assert!(count.matches(&[2]));
    assert!(
        count.matches(&[2, 0, 0, 0]),
        "zero padding is the same value"
    );
    assert!(!count.matches(&[3]));
    assert!(!count.matches(&[]));
    assert!(!count.matches(&[2, 0, 0, 0, 0, 0, 0, 0, 0]));
    let cob_id = steps[15];
    assert_eq!(cob_id.kind(), StepKind::CobId);
    assert!(cob_id.matches(&[0x85, 0x01, 0x00, 0x00]));
    assert!(cob_id.matches(&[0x85, 0x01, 0x00, 0x40]), "bit 30 ignored");
    assert!(!cob_id.matches(&[0x85, 0x01, 0x00, 0x80]), "still disabled");
    assert!(!cob_id.matches(&[0x86, 0x01, 0x00, 0x00]));
    let entry = steps[11];
    assert!(!entry.matches(&[0x20, 0x00, 0x64, 0x61]));
}

#[test]
fn check_refuses_what_cia_301_rules_out() {
    let base = tpdo1();
    let cases = [
        (
            PdoConfig {
                cob_id: PdoCobId(0x0000_0985),
                ..base
            },
            ConfigCheckError::CobId(CobIdError::OutOfRange(PdoCobId(0x985))),
        ),
        (
            PdoConfig {
                communication_index: 0x1400,
                ..base
            },
            ConfigCheckError::CommunicationIndex {
                direction: PdoDirection::Tpdo,
                index: 0x1400,
            },
        ),
        (
            PdoConfig {
                mapping_index: 0x1600,
                ..base
            },
            ConfigCheckError::MappingIndex {
                direction: PdoDirection::Tpdo,
                index: 0x1600,
            },
        ),
        (
            PdoConfig {
                entries: &[0x6064_0020, 0x6064_0020, 0x6041_0010],
                ..base
            },
            ConfigCheckError::TooLong { bits: 80 },
        ),
        (
            PdoConfig {
                entries: &[0x6041_0010, 0x6064_0000],
                ..base
            },
            ConfigCheckError::EmptyEntry {
                number: 2,
                value: 0x6064_0000,
            },
        ),
        (
            PdoConfig {
                entries: &[0x0005_0001; 65],
                ..base
            },
            ConfigCheckError::TooManyEntries(65),
        ),
        (
            base.with_transmission_type(TransmissionType::from_raw(241)),
            ConfigCheckError::TransmissionType {
                direction: PdoDirection::Tpdo,
                value: TransmissionType::from_raw(241),
            },
        ),
        (base.with_sync_start(241), ConfigCheckError::SyncStart(241)),
    ];
    for (config, error) in cases {
        assert_eq!(config.check(), Err(error));
    }
    // RTR-only types exist for TPDOs, not for RPDOs.
    assert_eq!(
        base.with_transmission_type(TransmissionType::from_raw(252))
            .check(),
        Ok(())
    );
    let rpdo =
        PdoConfig::new(PdoDirection::Rpdo, 1, PdoCobId(0x205), &STATUS_AND_POSITION).unwrap();
    assert_eq!(
        rpdo.with_transmission_type(TransmissionType::from_raw(253))
            .check(),
        Err(ConfigCheckError::TransmissionType {
            direction: PdoDirection::Rpdo,
            value: TransmissionType::from_raw(253)
        })
    );
    // 64 one-bit entries fill the PDO exactly.
    let bits = [0x0001_0001; 64];
    assert_eq!(
        PdoConfig {
            entries: &bits,
            ..base
        }
        .check(),
        Ok(())
    );
    assert_eq!(
        ConfigCheckError::TooLong { bits: 80 }.to_string(),
        "the mapping entries add up to 80 bits; a PDO carries at most 64"
    );
    assert_eq!(
        ConfigCheckError::MappingIndex {
            direction: PdoDirection::Tpdo,
            index: 0x1600
        }
        .to_string(),
        "mapping parameter 0x1600 is not one of an TPDO (0x1A00 to 0x1BFF)"
    );
}

/// A hand-written TPDO with a dummy entry (a 16-bit gap, data type 0x0006).
struct Gapped;

impl od::Pdo for Gapped {
    const DIRECTION: PdoDirection = PdoDirection::Tpdo;
    const NUMBER: u16 = 3;
    const COMMUNICATION_INDEX: u16 = 0x1802;
    const MAPPING_INDEX: u16 = 0x1A02;
    const LEN: usize = 4;
    const MAPPING: &'static [u32] = &[0x6041_0010, 0x0006_0010];
    fn default_cob_id(node: NodeId) -> Option<PdoCobId> {
        Some(PdoCobId(0x4000_0380 + u32::from(node.get())))
    }
    fn decode(_: &[u8]) -> Result<Self, PdoLengthError> {
        Ok(Gapped)
    }
    fn encode_into(&self, _: &mut [u8; 8]) -> usize {
        4
    }
}

#[test]
fn from_a_generated_pdo() {
    let node = NodeId::new(0x10).unwrap();
    let config = PdoConfig::from_pdo::<Gapped>(node).unwrap();
    assert_eq!(config.cob_id, PdoCobId(0x4000_0390));
    assert_eq!(config.check(), Ok(()));
    let writes: Vec<(u16, u8, Vec<u8>)> = config
        .steps()
        .filter(|s| s.action() == StepAction::Write)
        .map(|s| (s.index(), s.sub(), s.bytes().to_vec()))
        .collect();
    assert_eq!(
        writes,
        [
            (0x1802, 1, vec![0x90, 0x03, 0x00, 0xC0]),
            (0x1A02, 0, vec![0x00]),
            (0x1A02, 1, vec![0x10, 0x00, 0x41, 0x60]),
            (0x1A02, 2, vec![0x10, 0x00, 0x06, 0x00]),
            (0x1A02, 0, vec![0x02]),
            (0x1802, 1, vec![0x90, 0x03, 0x00, 0x40]),
        ]
    );
}

/// Runs `session` against a device that keeps what is written, except the
/// values `forget` names (read back as 0); returns the result and the
/// actions in order.
fn run_session(
    session: &mut ConfigSession<'_>,
    forget: &[(u16, u8)],
) -> (Result<(), ReadBackMismatch>, Vec<ConfigAction>) {
    let mut objects: BTreeMap<(u16, u8), Vec<u8>> = BTreeMap::new();
    let mut actions = Vec::new();
    loop {
        let action = session.poll_action();
        actions.push(action);
        match action {
            ConfigAction::Write(step) => {
                let kept = if forget.contains(&(step.index(), step.sub())) {
                    vec![0; step.bytes().len()]
                } else {
                    step.bytes().to_vec()
                };
                objects.insert((step.index(), step.sub()), kept);
                session.on_written();
            }
            ConfigAction::ReadBack(step) => {
                let read = objects
                    .get(&(step.index(), step.sub()))
                    .cloned()
                    .unwrap_or_default();
                session.on_read(&read);
            }
            ConfigAction::Done(result) => return (result, actions),
        }
    }
}

#[test]
fn session_runs_the_plan_in_order_without_io() {
    let config = tpdo1();
    let mut session = ConfigSession::new(&config).unwrap();
    let (result, actions) = run_session(&mut session, &[]);
    assert_eq!(result, Ok(()));
    let expected: Vec<ConfigAction> = config
        .steps()
        .map(|step| match step.action() {
            StepAction::Write => ConfigAction::Write(step),
            StepAction::ReadBack => ConfigAction::ReadBack(step),
        })
        .chain([ConfigAction::Done(Ok(()))])
        .collect();
    assert_eq!(actions, expected);
    // Done stays done.
    assert_eq!(session.poll_action(), ConfigAction::Done(Ok(())));
}

#[test]
fn session_reports_a_value_the_device_did_not_keep() {
    let config = tpdo1();
    let mut session = ConfigSession::new(&config).unwrap();
    // The event timer (sub 5) reads back as 0.
    let (result, _) = run_session(&mut session, &[(0x1800, 5)]);
    let mismatch = result.unwrap_err();
    assert_eq!(mismatch.step.kind(), StepKind::EventTimer);
    assert_eq!(mismatch.step.action(), StepAction::ReadBack);
    assert_eq!((mismatch.number, mismatch.total), (15, config.step_count()));
    assert_eq!(mismatch.read(), [0, 0]);
    assert_eq!(
        mismatch.to_string(),
        "PDO configuration step 15 of 16 failed: read back event timer of 0x1800 \
         (object 0x1800 sub 5): wrote 500 ms, read 0 ms; the device did not keep the value"
    );
    assert_eq!(session.poll_action(), ConfigAction::Done(Err(mismatch)));
}

#[test]
fn session_waits_for_the_answer_of_its_step() {
    let config = tpdo1();
    let mut session = ConfigSession::new(&config).unwrap();
    let first = session.poll_action();
    assert_eq!(session.poll_action(), first, "asked again: the same step");
    assert_eq!(session.position(), (1, config.step_count()));
    // A read answer while a write waits changes nothing.
    session.on_read(&[1, 2, 3, 4]);
    assert_eq!(session.position(), (1, config.step_count()));
    session.on_written();
    assert_eq!(session.position(), (2, config.step_count()));
    // An answer nobody asked for is ignored too.
    session.on_written();
    assert_eq!(session.position(), (2, config.step_count()));
}

#[test]
fn session_refuses_an_invalid_configuration() {
    let config = PdoConfig {
        entries: &[0x6064_0020, 0x6064_0020, 0x6041_0010],
        ..tpdo1()
    };
    assert_eq!(
        ConfigSession::new(&config).err(),
        Some(ConfigCheckError::TooLong { bits: 80 })
    );
}
