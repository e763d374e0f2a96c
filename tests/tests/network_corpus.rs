//! The bus files of ../shared/network-corpus read into the model: each
//! network's `bus.yml` (ros2_canopen's `defaults:` + `nodes:`) and its
//! `bus.expanded.yml` (the same network after ros2_canopen's expansion, as
//! dcfgen reads it) give equal slaves, and the model holds what the files
//! say (node ids, PDO sections, sdo items, the keys dcfgen does not use).

use std::path::{Path, PathBuf};

use eds2rust::network::model::{Bus, CobIdSetting, PdoSection, SlaveSection, Spot};
use eds2rust::network::{BusLoaded, read_file};
use eds2rust::read::Options;

/// `../shared/network-corpus/<name>`, or `None` after one visible line.
fn network(name: &str) -> Option<PathBuf> {
    let corpus = eds2rust_tests::network_corpus(&format!("network corpus read test ({name})"))?;
    Some(corpus.join(name))
}

fn read(path: &Path) -> (Bus, BusLoaded) {
    let mut loaded = read_file(path, &Options::default());
    assert!(
        !loaded.diagnostics.has_errors(),
        "{}:\n{}",
        path.display(),
        loaded.diagnostics.render()
    );
    let bus = loaded.bus.take().expect("a bus");
    (bus, loaded)
}

/// The (index, sub) of each entry a PDO section maps.
fn mapping(pdo: &PdoSection) -> Vec<(u16, u8)> {
    let items = pdo.mapping.as_ref().expect("a mapping");
    items.iter().map(|m| (m.index, m.sub_index)).collect()
}

/// A slave with every spot blanked, as text: what two spellings of one
/// network must share.
fn without_spots(slave: &SlaveSection) -> String {
    let mut s = slave.clone();
    let blank = Spot::default();
    s.spot = blank.clone();
    s.dcf.spot = blank.clone();
    // Blanks the spot of each optional field `$f` of `$on` that is set.
    macro_rules! blank_opt {
        ($on:expr; $($f:ident),*) => { $( if let Some(v) = &mut $on.$f { v.spot = blank.clone(); } )* };
    }
    blank_opt!(
        s;
        node_id,
        dcf_path,
        revision_number,
        serial_number,
        time_cob_id,
        heartbeat_multiplier,
        heartbeat_consumer,
        heartbeat_producer,
        retry_factor,
        guard_time,
        life_time_factor,
        boot,
        mandatory,
        reset_communication,
        software_file,
        software_version,
        configuration_file,
        restore_configuration
    );
    for v in s.error_behavior.values_mut() {
        v.spot = blank.clone();
    }
    for pdo in s.rpdo.values_mut().chain(s.tpdo.values_mut()) {
        pdo.spot = blank.clone();
        pdo.enabled.spot = blank.clone();
        blank_opt!(
            pdo;
            cob_id,
            transmission,
            inhibit_time,
            event_timer,
            event_deadline,
            sync_start
        );
        for item in pdo.mapping.iter_mut().flatten() {
            item.spot = blank.clone();
        }
    }
    for item in &mut s.sdo {
        item.spot = blank.clone();
    }
    *s.device = Default::default();
    format!("{s:#?}")
}

fn check_expansion(dir: &Path) -> (Bus, Bus) {
    let (bus, loaded) = read(&dir.join("bus.yml"));
    let (expanded, _) = read(&dir.join("bus.expanded.yml"));
    let names = |b: &Bus| b.slaves.iter().map(|s| s.name.clone()).collect::<Vec<_>>();
    assert_eq!(names(&bus), names(&expanded));
    for (a, b) in bus.slaves.iter().zip(&expanded.slaves) {
        assert_eq!(without_spots(a), without_spots(b), "slave {}", a.name);
        assert_eq!(a.device, b.device, "device of {}", a.name);
    }
    assert_eq!(bus.options, expanded.options);
    let mut master = expanded.master.clone();
    master.spot = bus.master.spot.clone();
    master.spots = bus.master.spots.clone();
    assert_eq!(bus.master, master);
    let extra = |b: &Bus| {
        let mut keys: Vec<_> = b
            .extra_keys
            .iter()
            .map(|k| (k.section.clone(), k.key.clone(), k.value.clone()))
            .collect();
        keys.sort();
        keys
    };
    assert_eq!(extra(&bus), extra(&expanded));
    println!(
        "{}: {} slaves, {} files, {} warnings",
        dir.display(),
        bus.slaves.len(),
        loaded.files.len(),
        loaded.diagnostics.warning_count()
    );
    (bus, expanded)
}

#[test]
fn prbt_pilz6() {
    let Some(dir) = network("prbt_pilz6") else {
        return;
    };
    let (bus, _) = check_expansion(&dir);
    assert_eq!(bus.options.dcf_path, "@BUS_CONFIG_PATH@");
    assert_eq!(bus.master.node_id, 1);
    assert_eq!(bus.master.sync_period, 10000);
    assert_eq!(bus.master.spots["sync_period"].line, 7);
    let names: Vec<_> = bus.slaves.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "prbt_joint_1",
            "prbt_joint_2",
            "prbt_joint_3",
            "prbt_joint_4",
            "prbt_joint_5",
            "prbt_joint_6"
        ]
    );
    for (n, slave) in bus.slaves.iter().enumerate() {
        assert_eq!(slave.effective_node_id(), Some(3 + n as u8));
        assert_eq!(slave.heartbeat_producer.as_ref().unwrap().value, 1000);
        assert_eq!(slave.dcf.value, "prbt_0_1.dcf");
        assert!(slave.device_file.ends_with("prbt_0_1.dcf"));
        assert_eq!(slave.tpdo.keys().copied().collect::<Vec<_>>(), [1, 2, 3, 4]);
        assert_eq!(slave.rpdo.keys().copied().collect::<Vec<_>>(), [1, 2]);
        let t1 = &slave.tpdo[&1];
        assert!(t1.enabled.value);
        assert_eq!(t1.cob_id.as_ref().unwrap().value, CobIdSetting::Auto);
        assert_eq!(t1.transmission.as_ref().unwrap().value, 1);
        assert_eq!(mapping(t1), [(0x6041, 0), (0x6061, 0)]);
        assert!(!slave.tpdo[&3].enabled.value);
        assert!(slave.tpdo[&3].mapping.is_none());
        assert_eq!(
            mapping(&slave.rpdo[&1]),
            [(0x6040, 0), (0x6060, 0), (0x60C1, 1)]
        );
        let sdo: Vec<_> = slave
            .sdo
            .iter()
            .map(|s| (s.index, s.sub_index, s.value))
            .collect();
        assert_eq!(sdo, [(0x6081, 0, 1000), (0x60C2, 1, 15), (0x6060, 0, 7)]);
        // Written in `defaults:`, at its line, under the node's name.
        assert_eq!(slave.sdo[1].spot.line, 22);
        assert_eq!(slave.sdo[1].spot.key, format!("{}.sdo[1]", slave.name));
    }
    // The node's own key is where the node is.
    assert_eq!(bus.slaves[0].node_id.as_ref().unwrap().spot.line, 59);
    let mut extra: Vec<_> = bus
        .extra_keys
        .iter()
        .filter(|k| k.section == "prbt_joint_1" || k.section == "master")
        .map(|k| format!("{}.{} = {}", k.section, k.key, k.value))
        .collect();
    extra.sort();
    assert_eq!(
        extra,
        [
            "master.driver = \"ros2_canopen::MasterDriver\"",
            "master.package = \"canopen_master_driver\"",
            "prbt_joint_1.driver = \"ros2_canopen::Cia402Driver\"",
            "prbt_joint_1.enable_lazy_load = false",
            "prbt_joint_1.package = \"canopen_402_driver\"",
            "prbt_joint_1.period = 10",
            "prbt_joint_1.position_mode = 7",
            "prbt_joint_1.scale_pos_from_dev = 0.00001745329252",
            "prbt_joint_1.scale_pos_to_dev = 57295.7795131",
            "prbt_joint_1.switching_state = 2",
        ]
    );
}

#[test]
fn trinamic_pd42() {
    let Some(dir) = network("trinamic_pd42") else {
        return;
    };
    let (bus, _) = check_expansion(&dir);
    assert_eq!(bus.master.node_id, 2);
    assert_eq!(bus.master.sync_period, 20000);
    assert_eq!(bus.slaves.len(), 1);
    let slave = &bus.slaves[0];
    assert_eq!(slave.name, "trinamic_pd42");
    assert_eq!(slave.effective_node_id(), Some(1));
    assert!(slave.device_file.ends_with("TMCM-1270.eds"));
    assert!(slave.rpdo.is_empty() && slave.tpdo.is_empty());
    let sdo: Vec<_> = slave
        .sdo
        .iter()
        .map(|s| (s.index, s.sub_index, s.value))
        .collect();
    assert_eq!(
        sdo,
        [
            (0x6081, 0, 500000),
            (0x6083, 0, 1000000),
            (0x6083, 0, 1000000),
            (0x6085, 0, 1000000),
            (0x6098, 0, 35),
            (0x60C2, 1, 50),
            (0x60C2, 2, -3),
        ]
    );
    let extra: Vec<_> = bus
        .extra_keys
        .iter()
        .map(|k| format!("{}.{}", k.section, k.key))
        .collect();
    for key in [
        "master.driver",
        "master.package",
        "trinamic_pd42.driver",
        "trinamic_pd42.package",
        "trinamic_pd42.polling",
    ] {
        assert!(extra.iter().any(|k| k == key), "{key} in {extra:?}");
    }
}
