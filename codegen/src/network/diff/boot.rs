//! What a node is given at boot besides its PDOs: the `sdo:` writes and
//! the other keys of its section.

use std::collections::BTreeMap;

use super::Wiring;
use super::out::{Out, Side, at_value};
use crate::diff::{Severity, Val, hex};
use crate::network::model::SlaveSection;
use crate::text::code_span;

/// `0x2000 sub 1` and, where the device names it, the object's name.
fn sdo_place(slave: &SlaveSection, (index, sub): (u16, u8)) -> (String, String) {
    let place = format!("0x{index:04X} sub {sub}");
    let name = slave
        .device
        .objects
        .get(&index)
        .map(|obj| {
            obj.entries
                .get(&sub)
                .map_or(obj.name.as_str(), |e| e.name.as_str())
        })
        .map_or(String::new(), |n| format!(" ({})", code_span(n)));
    (place, name)
}

/// The `sdo:` writes, by (index, sub-index): added, removed, changed
/// values, and the order of the writes kept by both.
pub(super) fn sdo_writes(o: &mut Out, os: &SlaveSection, ns: &SlaveSection) {
    let group = |s: &SlaveSection| {
        let mut writes: BTreeMap<(u16, u8), Vec<i128>> = BTreeMap::new();
        let mut order: Vec<(u16, u8)> = Vec::new();
        for item in &s.sdo {
            let key = (item.index, item.sub_index);
            writes.entry(key).or_default().push(item.value);
            if !order.contains(&key) {
                order.push(key);
            }
        }
        (writes, order)
    };
    let ((ow, oo), (nw, no)) = (group(os), group(ns));
    let val = |v: &[i128]| match v {
        [one] => Val::Int(*one),
        many => Val::List(many.iter().map(|v| hex(*v)).collect()),
    };
    let show = |v: &[i128]| {
        v.iter()
            .map(|v| hex(*v))
            .collect::<Vec<_>>()
            .join(", then ")
    };
    let mut keys: Vec<(u16, u8)> = ow.keys().chain(nw.keys()).copied().collect();
    keys.sort_unstable();
    keys.dedup();
    for key in keys {
        let at = (key.0, Some(key.1));
        let (place, name) = sdo_place(ns, key);
        match (ow.get(&key), nw.get(&key)) {
            (None, Some(n)) => o.push(
                Wiring::SdoWriteAdded,
                Severity::Compatible,
                at,
                &place,
                None,
                Some(val(n)),
                format!("boot writes {} to {place}{name}", show(n)),
            ),
            (Some(p), None) => {
                let (_, name) = sdo_place(os, key);
                o.push(
                    Wiring::SdoWriteRemoved,
                    Severity::Compatible,
                    at,
                    &place,
                    Some(val(p)),
                    None,
                    format!("boot no longer writes {} to {place}{name}", show(p)),
                );
            }
            (Some(p), Some(n)) if p != n => o.push(
                Wiring::SdoWriteChanged,
                Severity::Compatible,
                at,
                &place,
                Some(val(p)),
                Some(val(n)),
                format!("boot writes {place}{name}: {} → {}", show(p), show(n)),
            ),
            _ => {}
        }
    }
    let common = |order: &[(u16, u8)], other: &BTreeMap<(u16, u8), Vec<i128>>| -> Vec<String> {
        order
            .iter()
            .filter(|k| other.contains_key(k))
            .map(|&(i, s)| format!("0x{i:04X} sub {s}"))
            .collect()
    };
    let (oc, nc) = (common(&oo, &nw), common(&no, &ow));
    if oc != nc {
        let message = format!(
            "boot writes reordered: {} → {}",
            oc.join(", "),
            nc.join(", ")
        );
        o.push(
            Wiring::SdoWritesReordered,
            Severity::Compatible,
            (0, None),
            "sdo",
            Some(Val::List(oc)),
            Some(Val::List(nc)),
            message,
        );
    }
}

/// The slave's other keys, as written (absent: `default`: a change of
/// `options:` is reported there once), and the TIME COB-ID.
pub(super) fn settings(o: &mut Out, (_, on, os): Side, (_, nn, ns): Side) {
    o.setting("dcf_path", at_value(&os.dcf_path), at_value(&ns.dcf_path));
    o.setting(
        "retry_factor",
        at_value(&os.retry_factor),
        at_value(&ns.retry_factor),
    );
    o.setting(
        "time_cob_id",
        Some(&hex(on.time_cob_id.into())),
        Some(&hex(nn.time_cob_id.into())),
    );
    let serial = |s: &SlaveSection| at_value(&s.serial_number).map(|v| hex((*v).into()));
    o.setting("serial_number", serial(os).as_ref(), serial(ns).as_ref());
    let mut subs: Vec<u8> = os
        .error_behavior
        .keys()
        .chain(ns.error_behavior.keys())
        .copied()
        .collect();
    subs.sort_unstable();
    subs.dedup();
    for sub in subs {
        let get = |s: &SlaveSection| s.error_behavior.get(&sub).map(|a| a.value);
        o.setting(
            &format!("error_behavior.{sub}"),
            get(os).as_ref(),
            get(ns).as_ref(),
        );
    }
    // The boot keys, compared as written.
    macro_rules! settings {
        ($($key:ident),*) => {
            $(o.setting(stringify!($key), at_value(&os.$key), at_value(&ns.$key));)*
        };
    }
    settings!(
        boot,
        mandatory,
        reset_communication,
        software_file,
        software_version,
        configuration_file,
        restore_configuration
    );
}
