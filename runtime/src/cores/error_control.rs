//! The error-control frames' common decoding (CiA 301: 0x700 + node id,
//! one byte): boot-up, heartbeat and node-guarding replies alike, and the
//! NMT state they report ([`NmtState`], public as `nmt::NmtState`). The NMT
//! master, the heartbeat consumer and node guarding all read them through
//! [`parse_error_control`] and [`parse_state`].

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

byte_enum! {
    /// An NMT state as reported in boot-up, heartbeat and node-guarding frames
    /// (bits 6..0 of the state byte; bit 7, the guarding toggle, must be
    /// masked off before [`NmtState::from_byte`]).
    pub enum NmtState {
        /// The boot-up message: the node has just (re)initialised.
        BootUp = 0x00 => "boot-up",
        /// Stopped: only NMT and error control are active.
        Stopped = 0x04 => "stopped",
        /// Operational: all services, PDOs included, are active.
        Operational = 0x05 => "operational",
        /// Pre-operational: all services but PDOs are active.
        PreOperational = 0x7F => "pre-operational",
    }
}

/// Decodes an error-control frame into the node, the state it reports and
/// the toggle bit (bit 7, node guarding's); `None` for other frames and for
/// state bytes that are no CiA 301 state.
pub(crate) fn parse_state(frame: &Frame) -> Option<(NodeId, NmtState, bool)> {
    let (node, byte) = parse_error_control(frame)?;
    let state = NmtState::from_byte(byte & 0x7F)?;
    Some((node, state, byte & 0x80 != 0))
}

/// One optional entry per node id (1 to 127; slot 0 stays empty): what the
/// NMT master, the heartbeat consumer and node guarding keep of each node.
#[derive(Debug, Clone)]
pub(crate) struct PerNode<T>([Option<T>; 128]);

impl<T: Copy> PerNode<T> {
    /// No entry for any node.
    pub(crate) const fn new() -> PerNode<T> {
        PerNode([None; 128])
    }

    /// The entry of `node`.
    pub(crate) fn get(&self, node: NodeId) -> Option<&T> {
        self.0.get(usize::from(node.get()))?.as_ref()
    }

    /// The entry of `node`, to change.
    pub(crate) fn get_mut(&mut self, node: NodeId) -> Option<&mut T> {
        self.0.get_mut(usize::from(node.get()))?.as_mut()
    }

    /// Replaces the entry of `node` (`None` removes it); returns the old one.
    pub(crate) fn set(&mut self, node: NodeId, entry: Option<T>) -> Option<T> {
        let slot = self.0.get_mut(usize::from(node.get()))?;
        core::mem::replace(slot, entry)
    }

    /// Sets the entry of every node.
    pub(crate) fn set_all(&mut self, entry: Option<T>) {
        for slot in self.0.iter_mut().skip(1) {
            *slot = entry;
        }
    }

    /// The entries.
    pub(crate) fn iter(&self) -> impl Iterator<Item = &T> {
        self.0.iter().flatten()
    }

    /// The nodes with an entry, in id order, with their entries.
    pub(crate) fn iter_mut(&mut self) -> impl Iterator<Item = (NodeId, &mut T)> {
        self.0.iter_mut().enumerate().filter_map(|(i, slot)| {
            let node = u8::try_from(i).ok().and_then(NodeId::new)?;
            Some((node, slot.as_mut()?))
        })
    }

    /// The first node from slot `from` on (wrapping after 127) whose entry
    /// `pick` takes, for serving the nodes in turn.
    pub(crate) fn next_from(
        &mut self,
        from: usize,
        mut pick: impl FnMut(&mut T) -> bool,
    ) -> Option<NodeId> {
        let len = self.0.len();
        (0..len).map(|step| (from + step) % len).find_map(|i| {
            let entry = self.0.get_mut(i)?.as_mut()?;
            if pick(entry) {
                u8::try_from(i).ok().and_then(NodeId::new)
            } else {
                None
            }
        })
    }
}
