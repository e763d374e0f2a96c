//! IR → EDS (CiA 306): [`to_eds`] writes a [`Device`] as an EDS that our
//! reader reads back into the same IR (see the list of stated differences in
//! `tests/tests/export_eds.rs`) and that python-canopen 2.4.1 loads without a
//! warning.
//!
//! Layout: LF line ends, UTF-8, one blank line between sections; `[FileInfo]`,
//! `[DeviceInfo]`, `[DummyUsage]`, `[Comments]` (when there are comments),
//! `[DeviceComissioning]` (when the device came from a DCF), the three object
//! lists, then every object in index order, each followed by its sub-objects.
//!
//! Values:
//! - integers in decimal below 10, otherwise `0x` hex; a signed type's value,
//!   and any negative value, always in decimal (`-5`), so that no reader takes
//!   a hex literal for a two's-complement pattern;
//! - `$NODEID+offset` for node-relative values (`$NODEID+0` for offset 0,
//!   since python-canopen cannot read a bare `$NODEID`);
//! - REAL32/REAL64 as the shortest decimal that reads back to the same value
//!   (`inf`, `-inf` and `NaN` as such);
//! - VISIBLE_STRING/UNICODE_STRING as the text, OCTET_STRING/DOMAIN as hex
//!   bytes without spaces (`010AFF`); an empty string or byte string is an
//!   empty value (`DefaultValue=`), which both readers take as "empty".
//!
//! What an INI line cannot hold, and what is done about it (all text values,
//! names included):
//! - line breaks and other control characters (except TAB) become a space;
//! - leading and trailing white space is dropped (every INI reader trims);
//! - in values that are not free text (DefaultValue, LowLimit, HighLimit,
//!   ParameterValue of strings, FileVersion, dates), a `;` preceded by white
//!   space would start an inline comment: the white space before such a `;`
//!   is dropped (`a ; b` is written `a; b`). Free-text keys (ParameterName,
//!   Denotation, Description, names in `[DeviceInfo]`, `LineN`) are written as
//!   they are: CiA 306 and our reader take their whole line (python-canopen
//!   cuts such a name at the `;`).

use std::fmt::Write as _;

use crate::ir::{DataType, Device, Entry, Literal, Object, ObjectKind, Value, ValueKind};

/// Writes `device` as a CiA 306 EDS (LF line ends). Never panics.
///
/// Written: file info (with `EDSVersion=4.0` and `CreatedBy=eds2rust`),
/// identity, capabilities (bit rates with a `BaudRate_` key, PDO counts —
/// counted from the communication objects when the device does not state
/// them —, `LSS_Supported` from the capabilities or the network's LSS facts),
/// dummy usage, comments, DCF commissioning and parameter values, and every
/// object and entry with type, access, PDO mapping, default, limits, flags and
/// denotation. CompactSubObj objects are written with their expanded
/// sub-objects. Left out (CiA 306 cannot carry them): the semantic layer,
/// PDO labels, error tables, variants (see [`to_eds_variant`]) and the
/// network's node id and bit rate.
pub fn to_eds(device: &Device) -> String {
    let mut w = Writer::default();
    file_info(&mut w, device);
    device_info(&mut w, device);
    w.section("DummyUsage");
    for code in 1u16..=0x1B {
        let used = device.dummy_usage.contains(&DataType::from_code(code));
        // python-canopen requires Dummy0001..Dummy0007; the others only when used.
        if code <= 7 || used {
            w.key(&format!("Dummy{code:04X}"), flag(used));
        }
    }
    if !device.comments.is_empty() {
        w.section("Comments");
        w.key("Lines", &device.comments.len().to_string());
        for (i, line) in device.comments.iter().enumerate() {
            w.key(&format!("Line{}", i + 1), &free_text(line));
        }
    }
    commissioning(&mut w, device);
    object_lists(&mut w, device);
    for object in device.objects.values() {
        write_object(&mut w, object);
    }
    w.out
}

/// Applies the product variant `variant` ([`apply_variant`](super::apply_variant))
/// and writes the result with [`to_eds`].
///
/// Errors: an unknown variant, or an override of an entry the device lacks.
pub fn to_eds_variant(device: &Device, variant: &str) -> Result<String, super::VariantError> {
    super::apply_variant(device, variant).map(|d| to_eds(&d))
}

/// The text of a literal as an EDS value of `data_type`.
///
/// See the module documentation for the rules; the value, not the source
/// spelling ([`Literal::text`]), is written.
pub fn literal_text(literal: &Literal, data_type: DataType) -> String {
    match &literal.value {
        Value::Integer(v) => {
            let signed = matches!(
                data_type.value_kind(),
                Some(ValueKind::Integer { signed: true, .. })
            );
            let n = int_text(*v, signed);
            if literal.plus_node_id {
                format!("$NODEID+{n}")
            } else {
                n
            }
        }
        Value::Real(v) => real_text(*v, data_type),
        Value::Text(s) => value_text(s),
        Value::Bytes(b) => b.iter().fold(String::new(), |mut s, x| {
            let _ = write!(s, "{x:02X}");
            s
        }),
    }
}

/// Decimal below 10, for signed types and for negative values; `0x` hex otherwise.
fn int_text(v: i128, signed: bool) -> String {
    if signed || v < 10 {
        v.to_string()
    } else {
        format!("0x{v:X}")
    }
}

/// The shortest decimal that reads back (as our reader reads REAL32: parsed
/// as f64, then rounded to f32) to the same value.
fn real_text(v: f64, data_type: DataType) -> String {
    if data_type == DataType::Real32 {
        let single = v as f32;
        let text = single.to_string();
        if f64::from(single).to_bits() == v.to_bits()
            && text.parse::<f64>().map(|x| (x as f32).to_bits()) == Ok(single.to_bits())
        {
            return text;
        }
    }
    v.to_string()
}

/// Free text (names, descriptions): control characters become spaces, the
/// ends are trimmed.
fn free_text(s: &str) -> String {
    let cleaned: String = s
        .chars()
        .map(|c| if c.is_control() && c != '\t' { ' ' } else { c })
        .collect();
    cleaned.trim().to_string()
}

/// A value that is not free text: as [`free_text`], and white space directly
/// before a `;` is dropped so that the `;` does not start an inline comment.
fn value_text(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in free_text(s).chars() {
        if c == ';' {
            let kept = out.trim_end().len();
            out.truncate(kept);
        }
        out.push(c);
    }
    out
}

fn flag(b: bool) -> &'static str {
    if b { "1" } else { "0" }
}

/// Accumulates INI text.
#[derive(Default)]
struct Writer {
    out: String,
}

impl Writer {
    fn section(&mut self, name: &str) {
        if !self.out.is_empty() {
            self.out.push('\n');
        }
        self.out.push('[');
        self.out.push_str(name);
        self.out.push_str("]\n");
    }

    fn key(&mut self, key: &str, value: &str) {
        self.out.push_str(key);
        self.out.push('=');
        self.out.push_str(value);
        self.out.push('\n');
    }

    fn opt_text(&mut self, key: &str, value: Option<&String>, free: bool) {
        if let Some(v) = value {
            let v = if free { free_text(v) } else { value_text(v) };
            self.key(key, &v);
        }
    }

    fn opt_num(&mut self, key: &str, value: Option<impl Into<i128>>) {
        if let Some(v) = value {
            self.key(key, &int_text(v.into(), false));
        }
    }

    fn opt_flag(&mut self, key: &str, value: Option<bool>) {
        if let Some(v) = value {
            self.key(key, flag(v));
        }
    }
}

fn file_info(w: &mut Writer, device: &Device) {
    let fi = &device.file_info;
    w.section("FileInfo");
    w.opt_text("FileName", fi.file_name.as_ref(), true);
    w.opt_text("FileVersion", fi.file_version.as_ref(), false);
    w.opt_text("FileRevision", fi.file_revision.as_ref(), false);
    w.key("EDSVersion", "4.0");
    w.opt_text("Description", fi.description.as_ref(), true);
    w.opt_text("CreationTime", fi.creation_time.as_ref(), false);
    w.opt_text("CreationDate", fi.creation_date.as_ref(), false);
    w.key("CreatedBy", "eds2rust");
    w.opt_text("ModificationTime", fi.modification_time.as_ref(), false);
    w.opt_text("ModificationDate", fi.modification_date.as_ref(), false);
    w.opt_text("ModifiedBy", fi.modified_by.as_ref(), true);
}

fn device_info(w: &mut Writer, device: &Device) {
    let id = &device.identity;
    let caps = &device.capabilities;
    w.section("DeviceInfo");
    w.opt_text("VendorName", id.vendor_name.as_ref(), true);
    w.opt_num("VendorNumber", id.vendor_number);
    w.opt_text("ProductName", id.product_name.as_ref(), true);
    w.opt_num("ProductNumber", id.product_number);
    w.opt_num("RevisionNumber", id.revision_number);
    w.opt_text("OrderCode", id.order_code.as_ref(), true);
    for rate in [10u32, 20, 50, 125, 250, 500, 800, 1000] {
        w.key(
            &format!("BaudRate_{rate}"),
            flag(caps.baud_rates.contains(&rate)),
        );
    }
    w.opt_flag("SimpleBootUpMaster", caps.simple_boot_up_master);
    w.opt_flag("SimpleBootUpSlave", caps.simple_boot_up_slave);
    w.opt_num("Granularity", caps.granularity);
    w.opt_num("DynamicChannelsSupported", caps.dynamic_channels_supported);
    w.opt_flag("GroupMessaging", caps.group_messaging);
    let count = |range: std::ops::RangeInclusive<u16>| {
        u16::try_from(device.objects.range(range).count()).unwrap_or(u16::MAX)
    };
    w.opt_num(
        "NrOfRXPDO",
        Some(caps.nr_of_rx_pdo.unwrap_or_else(|| count(0x1400..=0x15FF))),
    );
    w.opt_num(
        "NrOfTXPDO",
        Some(caps.nr_of_tx_pdo.unwrap_or_else(|| count(0x1800..=0x19FF))),
    );
    let lss = caps
        .lss_supported
        .or(device.network.lss.as_ref().map(|_| true));
    w.opt_flag("LSS_Supported", lss);
}

fn commissioning(w: &mut Writer, device: &Device) {
    let Some(c) = &device.commissioning else {
        return;
    };
    // CiA 306 spelling. Numbers in decimal: python-canopen reads Baudrate with int(x).
    w.section("DeviceComissioning");
    if let Some(n) = c.node_id {
        w.key("NodeID", &n.to_string());
    }
    w.opt_text("NodeName", c.node_name.as_ref(), true);
    if let Some(b) = c.baud_rate {
        w.key("Baudrate", &b.to_string());
    }
    if let Some(n) = c.net_number {
        w.key("NetNumber", &n.to_string());
    }
    w.opt_text("NetworkName", c.network_name.as_ref(), true);
    w.opt_flag("CANopenManager", c.canopen_manager);
    if let Some(n) = c.lss_serial_number {
        w.key("LSS_SerialNumber", &n.to_string());
    }
}

fn object_lists(w: &mut Writer, device: &Device) {
    let mandatory = |i: u16| matches!(i, 0x1000 | 0x1001 | 0x1018);
    let lists: [(&str, &dyn Fn(u16) -> bool); 3] = [
        ("MandatoryObjects", &mandatory),
        ("OptionalObjects", &|i| {
            !mandatory(i) && ((0x1000..=0x1FFF).contains(&i) || i >= 0x6000)
        }),
        ("ManufacturerObjects", &|i| (0x2000..=0x5FFF).contains(&i)),
    ];
    for (name, belongs) in lists {
        let indices: Vec<u16> = device
            .objects
            .keys()
            .copied()
            .filter(|&i| belongs(i))
            .collect();
        w.section(name);
        w.key("SupportedObjects", &indices.len().to_string());
        for (n, index) in indices.iter().enumerate() {
            w.key(&(n + 1).to_string(), &format!("0x{index:04X}"));
        }
    }
}

fn write_object(w: &mut Writer, object: &Object) {
    w.section(&format!("{:04X}", object.index));
    w.key("ParameterName", &free_text(&object.name));
    w.key("ObjectType", &format!("0x{:X}", object.kind.code()));
    match object.kind {
        ObjectKind::Var | ObjectKind::Domain | ObjectKind::DefType => {
            // One section holds the object and its single entry; where both
            // carry flags or a denotation, the entry's win.
            let entry = object.entries.get(&0);
            let obj_flags = entry.and_then(|e| e.obj_flags).or(object.obj_flags);
            let denotation = entry
                .and_then(|e| e.denotation.as_ref())
                .or(object.denotation.as_ref());
            if let Some(entry) = entry {
                entry_keys(w, entry);
            }
            w.opt_num("ObjFlags", obj_flags);
            w.opt_text("Denotation", denotation, true);
        }
        ObjectKind::Array | ObjectKind::Record | ObjectKind::DefStruct => {
            w.key("SubNumber", &format!("0x{:X}", object.entries.len()));
            w.opt_num("ObjFlags", object.obj_flags);
            w.opt_text("Denotation", object.denotation.as_ref(), true);
            for (sub, entry) in &object.entries {
                w.section(&format!("{:04X}sub{sub:X}", object.index));
                w.key("ParameterName", &free_text(&entry.name));
                w.key("ObjectType", "0x7");
                entry_keys(w, entry);
                w.opt_num("ObjFlags", entry.obj_flags);
                w.opt_text("Denotation", entry.denotation.as_ref(), true);
            }
        }
    }
}

/// The value-carrying keys of one entry (not its name, flags or denotation).
fn entry_keys(w: &mut Writer, entry: &Entry) {
    let t = entry.data_type;
    w.key("DataType", &format!("0x{:04X}", t.code()));
    w.key("AccessType", entry.access.as_str());
    let mut value = |key: &str, literal: &Option<Literal>| {
        if let Some(l) = literal {
            w.key(key, &literal_text(l, t));
        }
    };
    value("DefaultValue", &entry.default);
    value("LowLimit", &entry.low_limit);
    value("HighLimit", &entry.high_limit);
    value("ParameterValue", &entry.parameter_value);
    w.key("PDOMapping", flag(entry.pdo_mappable));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eds::{Options, read_bytes};
    use crate::ir::{Access, Origin};

    fn lit(value: Value, plus_node_id: bool) -> Literal {
        Literal {
            value,
            plus_node_id,
            text: String::new(),
        }
    }

    fn text(value: Value, t: DataType) -> String {
        literal_text(&lit(value, false), t)
    }

    #[test]
    fn integers_node_relative_and_negative() {
        use DataType::*;
        assert_eq!(text(Value::Integer(5), Unsigned8), "5");
        assert_eq!(text(Value::Integer(0x180), Unsigned32), "0x180");
        assert_eq!(text(Value::Integer(-5), Integer16), "-5");
        assert_eq!(text(Value::Integer(300), Integer16), "300");
        assert_eq!(text(Value::Integer(-1), Unsigned8), "-1");
        let rel = |v| literal_text(&lit(Value::Integer(v), true), Unsigned32);
        assert_eq!(rel(0x180), "$NODEID+0x180");
        assert_eq!(rel(0), "$NODEID+0");
        assert_eq!(rel(-2), "$NODEID+-2");
        assert_eq!(
            literal_text(&lit(Value::Integer(-2), true), Integer32),
            "$NODEID+-2"
        );
    }

    #[test]
    fn reals_round_trip_exactly() {
        use crate::eds::number::parse_value;
        let cases = [
            (0.1f32 as f64, DataType::Real32, "0.1"),
            (-2.5, DataType::Real32, "-2.5"),
            (0.1, DataType::Real64, "0.1"),
            (1e300, DataType::Real64, ""),
            (f64::INFINITY, DataType::Real64, "inf"),
            (f32::MAX as f64, DataType::Real32, ""),
            (1e-45f32 as f64, DataType::Real32, ""),
        ];
        for (v, t, expected) in cases {
            let s = text(Value::Real(v), t);
            if !expected.is_empty() {
                assert_eq!(s, expected);
            }
            let back = parse_value(&s, t).unwrap().unwrap().literal.value;
            assert_eq!(back, Value::Real(v), "{s}");
        }
        assert_eq!(text(Value::Real(f64::NAN), DataType::Real32), "NaN");
    }

    #[test]
    fn strings_and_bytes() {
        use DataType::*;
        assert_eq!(
            text(Value::Bytes(vec![1, 0x0A, 0xFF]), OctetString),
            "010AFF"
        );
        assert_eq!(text(Value::Bytes(vec![]), Domain), "");
        assert_eq!(text(Value::Text(String::new()), VisibleString), "");
        assert_eq!(
            text(Value::Text(" a ;b\nc; d ".into()), VisibleString),
            "a;b c; d"
        );
        assert_eq!(free_text("Name ;x\r\n"), "Name ;x");
    }

    fn entry(sub: u8, t: DataType, default: Option<Value>) -> Entry {
        Entry {
            subindex: sub,
            name: format!("Entry {sub}\nsecond line"),
            data_type: t,
            access: Access::Rw,
            pdo_mappable: true,
            default: default.map(|v| lit(v, false)),
            low_limit: None,
            high_limit: None,
            parameter_value: None,
            obj_flags: None,
            denotation: None,
            semantics: Default::default(),
            rust_name: None,
            origin: Origin::default(),
        }
    }

    #[test]
    fn export_reads_back_without_diagnostics() {
        let mut device = Device {
            comments: vec!["first".into(), String::new()],
            dummy_usage: vec![DataType::Unsigned8],
            ..Device::default()
        };
        device.capabilities.baud_rates = vec![125, 333, 1000];
        let mut array = Object {
            index: 0x2000,
            name: "Array".into(),
            kind: ObjectKind::Array,
            entries: Default::default(),
            obj_flags: Some(1),
            denotation: None,
            compact_sub_obj: None,
            rust_name: None,
            origin: Origin::default(),
        };
        array.entries.insert(
            0,
            Box::new(Entry::highest_subindex(0x1B, Origin::default())),
        );
        for (sub, t, v) in [
            (1, DataType::Integer8, Value::Integer(-128)),
            (2, DataType::VisibleString, Value::Text(String::new())),
            (0x1B, DataType::OctetString, Value::Bytes(vec![])),
        ] {
            array.entries.insert(sub, Box::new(entry(sub, t, Some(v))));
        }
        device.objects.insert(0x2000, array);
        let out = to_eds(&device);
        assert!(out.contains("[2000sub1B]\nParameterName=Entry 27 second line\n"));
        assert!(out.contains("BaudRate_125=1\n") && !out.contains("333"));
        let loaded = read_bytes("export.eds", out.as_bytes(), &Options::strict());
        assert!(
            loaded.diagnostics.is_empty(),
            "{:?}\n{out}",
            loaded.diagnostics
        );
        let back = loaded.device.unwrap();
        // The reader also takes the `Lines=2` key for a comment line.
        assert!(
            back.comments.ends_with(&device.comments),
            "{:?}",
            back.comments
        );
        assert_eq!(back.dummy_usage, device.dummy_usage);
        assert_eq!(back.capabilities.baud_rates, vec![125, 1000]);
        let entries = &back.objects[&0x2000].entries;
        for (sub, e) in &device.objects[&0x2000].entries {
            let value = |e: &Entry| e.default.as_ref().map(|l| l.value.clone());
            assert_eq!(value(&entries[sub]), value(e), "sub {sub}");
        }
    }

    #[test]
    fn never_panics_on_odd_ir() {
        let mut device = Device::default();
        let mut var = Object {
            index: 0,
            name: "\n".into(),
            kind: ObjectKind::Var,
            entries: Default::default(),
            obj_flags: None,
            denotation: Some("\r".into()),
            compact_sub_obj: Some(3),
            rust_name: None,
            origin: Origin::default(),
        };
        let mut e = entry(0, DataType::Other(0xFFFF), Some(Value::Integer(i128::MIN)));
        e.low_limit = Some(lit(Value::Real(f64::NAN), true));
        e.high_limit = Some(lit(Value::Bytes(vec![0; 3]), true));
        var.entries.insert(0, Box::new(e));
        device.objects.insert(0, var);
        let out = to_eds(&device);
        assert!(out.contains("[0000]"));
    }
}
