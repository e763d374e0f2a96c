//! The error-control frames' common decoding (CiA 301: 0x700 + node id,
//! one byte): boot-up, heartbeat and node-guarding replies alike. The NMT
//! master, the heartbeat consumer and node guarding all read them through
//! [`parse_error_control`].

use crate::Frame;
use crate::od::NodeId;

/// Decodes an error-control data frame (boot-up, heartbeat or node-guarding
/// reply): COB-ID 0x701..=0x77F, not remote, exactly one data byte. Returns
/// the node and the raw byte (toggle bit included).
pub fn parse_error_control(frame: &Frame) -> Option<(NodeId, u8)> {
    if frame.is_remote() {
        return None;
    }
    let id = frame.standard_id()?;
    let node = NodeId::new(u8::try_from(id.checked_sub(0x700)?).ok()?)?;
    match *frame.data() {
        [byte] => Some((node, byte)),
        _ => None,
    }
}
