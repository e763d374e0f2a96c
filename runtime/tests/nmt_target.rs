//! No invalid node id reaches the bus as a broadcast: every `u8` goes
//! through each public way of naming an NMT target, and the master sends
//! what it built. Node 0 on the wire comes only from `NmtTarget::All`.

use eds2rust_runtime::blocking::Master;
use eds2rust_runtime::master;
use eds2rust_runtime::nmt::{InvalidNodeId, NmtCommand, NmtTarget, command_frame};
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::transport::virtual_bus::VirtualBus;

#[test]
fn only_nmt_target_all_sends_node_zero() {
    let bus = VirtualBus::new();
    let monitor = bus.attach();
    let core = master::Master::new(NodeId::new(1).unwrap(), None);
    let mut m = Master::new(bus.attach(), core);
    for id in 0..=u8::MAX {
        let valid = (1..=127).contains(&id);
        // The ways of building a target from a number.
        let from_u8 = NmtTarget::try_from(id);
        let from_node = NodeId::new(id).map(NmtTarget::from);
        let built = NodeId::new(id).map(NmtTarget::Node);
        assert_eq!(from_u8.is_ok(), valid, "{id}");
        assert_eq!(from_node.is_some(), valid, "{id}");
        if !valid {
            assert_eq!(from_u8, Err(InvalidNodeId(id)));
            assert!(from_u8.unwrap_err().to_string().contains("NmtTarget::All"));
        }
        let targets = [from_u8.ok(), from_node, built];
        for target in targets.into_iter().flatten() {
            m.nmt(NmtCommand::ResetNode, target).unwrap();
            let frame = monitor.try_recv().expect("the command went out");
            assert_eq!(frame.data(), [0x81, id], "{target}");
        }
        // A `NodeId` goes in as it is.
        if let Some(node) = NodeId::new(id) {
            m.nmt(NmtCommand::Stop, node).unwrap();
            assert_eq!(monitor.try_recv().unwrap().data(), [0x02, id]);
        }
        assert_eq!(monitor.try_recv(), None);
    }
    m.nmt(NmtCommand::ResetNode, NmtTarget::All).unwrap();
    assert_eq!(monitor.try_recv().unwrap().data(), [0x81, 0]);
    assert_eq!(
        command_frame(NmtCommand::ResetNode, NmtTarget::All).data(),
        [0x81, 0]
    );
}
