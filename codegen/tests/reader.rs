//! Reader rules of docs/eds-reader.md that the corpus does not pin down by
//! itself, each checked on a small hand-written file.

use eds2rust::eds::{Options, read_bytes};
use eds2rust::ir::{DataType, Device, ObjectKind, Value};

fn read(text: &str) -> (Device, Vec<&'static str>) {
    let loaded = read_bytes("t.eds", text.as_bytes(), Options::default());
    let codes = loaded.diagnostics.iter().map(|d| d.code).collect();
    (loaded.device.expect("device"), codes)
}

fn default(device: &Device, index: u16, sub: u8) -> Option<Value> {
    device.objects[&index].entries[&sub]
        .default
        .as_ref()
        .map(|l| l.value.clone())
}

#[test]
fn sub_sections_before_their_parent_and_lower_case_names() {
    let (device, codes) = read(
        "[optionalobjects]\nsupportedobjects=1\n1=0x2000\n\
         [2000SUB1]\nparametername=Item\ndatatype=0x0006\naccesstype=RW\ndefaultvalue=017\n\
         [2000sub0]\nParameterName=Count\nDataType=0x0005\nAccessType=ro\nDefaultValue=1\n\
         [2000]\nParameterName=Table\nObjectType=0x8\nSubNumber=2\n",
    );
    assert!(codes.is_empty(), "{codes:?}");
    let table = &device.objects[&0x2000];
    assert_eq!(table.kind, ObjectKind::Array);
    assert_eq!(table.entries.len(), 2);
    assert_eq!(
        default(&device, 0x2000, 1),
        Some(Value::Integer(15)),
        "017 is octal"
    );
}

#[test]
fn compact_record_with_names_and_dcf_values() {
    let (device, codes) = read(
        "[OptionalObjects]\nSupportedObjects=1\n1=0x1016\n\
         [1016]\nParameterName=Consumer heartbeat time\nObjectType=0x9\nCompactSubObj=3\n\
         DataType=0x0007\nAccessType=rw\nDefaultValue=0\n\
         [1016Name]\nNrOfEntries=1\n2=Safety controller\n\
         [1016Value]\nNrOfEntries=2\n1=0x00050064\n3=$NODEID+0x10\n",
    );
    assert!(codes.is_empty(), "{codes:?}");
    let object = &device.objects[&0x1016];
    assert_eq!(
        (object.kind, object.compact_sub_obj),
        (ObjectKind::Record, Some(3))
    );
    assert_eq!(object.entries.len(), 4);
    assert_eq!(default(&device, 0x1016, 0), Some(Value::Integer(3)));
    assert_eq!(object.entries[&1].name, "Consumer heartbeat time1");
    assert_eq!(object.entries[&2].name, "Safety controller");
    let pv = |sub: u8| object.entries[&sub].parameter_value.clone();
    assert_eq!(pv(1).map(|l| l.value), Some(Value::Integer(0x0005_0064)));
    assert!(pv(2).is_none());
    let third = pv(3).expect("value of sub 3");
    assert!(third.plus_node_id);
    assert_eq!(third.resolve(Some(5)), Value::Integer(0x15));
}

#[test]
fn values_formulas_reals_and_dummies() {
    let (device, codes) = read(
        "[DummyUsage]\nDummy0002=1\nDummy0007=1\n\
         [OptionalObjects]\nSupportedObjects=4\n1=0x1800\n2=0x2001\n3=0x2002\n4=0x2003\n\
         [1800]\nParameterName=COB-ID\nDataType=0x0007\nAccessType=rw\nDefaultValue= 0x180 + $nodeid \n\
         [2001]\nParameterName=Gain\nDataType=0x0008\nAccessType=rw\nDefaultValue=0x3FC00000\n\
         [2002]\nParameterName=Offset\nDataType=0x0003\nAccessType=rw\nDefaultValue=0xFFFE\n\
         [2003]\nParameterName=Key\nDataType=0x000A\nAccessType=rw\nDefaultValue=01 0a FF\n",
    );
    assert!(codes.is_empty(), "{codes:?}");
    assert_eq!(
        device.dummy_usage,
        [DataType::Integer8, DataType::Unsigned32]
    );
    let cob = device.objects[&0x1800].entries[&0].default.clone().unwrap();
    assert!(cob.plus_node_id);
    assert_eq!(cob.resolve(Some(32)), Value::Integer(0x1A0));
    assert_eq!(default(&device, 0x2001, 0), Some(Value::Real(1.5)));
    assert_eq!(default(&device, 0x2002, 0), Some(Value::Integer(-2)));
    assert_eq!(
        default(&device, 0x2003, 0),
        Some(Value::Bytes(vec![1, 10, 255]))
    );
}

#[test]
fn object_lists_both_ways_and_identity_from_1018() {
    let (device, codes) = read(
        "[MandatoryObjects]\nSupportedObjects=2\n1=0x1000\n2=0x1018\n\
         [1000]\nParameterName=Device type\nDataType=0x0007\nAccessType=ro\n\
         [1018]\nParameterName=Identity\nObjectType=0x9\nSubNumber=2\n\
         [1018sub0]\nParameterName=Count\nDataType=0x0005\nAccessType=ro\nDefaultValue=1\n\
         [1018sub1]\nParameterName=Vendor-ID\nDataType=0x0007\nAccessType=ro\nDefaultValue=0x0000ABCD\n\
         [2000]\nParameterName=Unlisted\nDataType=0x0005\nAccessType=rw\n",
    );
    assert_eq!(codes, ["eds::unlisted-object"]);
    assert!(
        device.objects.contains_key(&0x2000),
        "an unlisted object is read"
    );
    assert_eq!(device.identity.vendor_number, Some(0xABCD));
    let (device, codes) = read(
        "[OptionalObjects]\nSupportedObjects=2\n1=0x2000\n2=0x2001\n[2000]\nParameterName=A\nDataType=0x0005\nAccessType=rw\n",
    );
    assert_eq!(codes, ["eds::missing-object-section"]);
    assert!(
        !device.objects.contains_key(&0x2001),
        "a listed object without a section is left out"
    );
}
