use super::*;
use crate::od::{NodeId, PdoLengthError};

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
    PdoConfig::new(PdoDirection::Tpdo, 1, 0x185, &STATUS_AND_POSITION)
        .unwrap()
        .with_transmission_type(254)
        .with_inhibit_time(100)
        .with_event_timer(500)
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
    let config = PdoConfig::new(PdoDirection::Rpdo, 2, 0x305, &entries)
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
    let empty = PdoConfig::new(PdoDirection::Tpdo, 512, 0x8000_0000, &[]).unwrap();
    assert_eq!(
        (empty.communication_index, empty.mapping_index),
        (0x19FF, 0x1BFF)
    );
    assert_eq!(plan(&empty).len(), 6);
    assert!(PdoConfig::new(PdoDirection::Tpdo, 0, 0x185, &[]).is_none());
    assert!(PdoConfig::new(PdoDirection::Tpdo, 513, 0x185, &[]).is_none());
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
                cob_id: 0x2000_0185,
                ..base
            },
            ConfigCheckError::CobId(CobIdError::Extended(0x2000_0185)),
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
            base.with_transmission_type(241),
            ConfigCheckError::TransmissionType {
                direction: PdoDirection::Tpdo,
                value: 241,
            },
        ),
        (base.with_sync_start(241), ConfigCheckError::SyncStart(241)),
    ];
    for (config, error) in cases {
        assert_eq!(config.check(), Err(error));
    }
    // RTR-only types exist for TPDOs, not for RPDOs.
    assert_eq!(base.with_transmission_type(252).check(), Ok(()));
    let rpdo = PdoConfig::new(PdoDirection::Rpdo, 1, 0x205, &STATUS_AND_POSITION).unwrap();
    assert_eq!(
        rpdo.with_transmission_type(253).check(),
        Err(ConfigCheckError::TransmissionType {
            direction: PdoDirection::Rpdo,
            value: 253
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
    fn default_cob_id(node: NodeId) -> Option<u32> {
        Some(0x4000_0380 + u32::from(node.get()))
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
    assert_eq!(config.cob_id, 0x4000_0390);
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
