//! The bus the live commands talk over: a SocketCAN interface (Linux), or
//! in tests any [`Bus`] (a port of the virtual bus). It also feeds the
//! progress bar of a running transfer: every frame a transfer sends carries
//! up to 7 bytes of its data.

use std::io;
use std::io::IsTerminal;
use std::time::Duration;

use eds2rust_runtime::Frame;
use eds2rust_runtime::blocking::Master;
use eds2rust_runtime::master;
use eds2rust_runtime::od::NodeId;
use eds2rust_runtime::sdo::Channel;
use eds2rust_runtime::sdo::client::ClientConfig;
use eds2rust_runtime::transport::Bus;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::LiveError;

/// The node id of the master's own (never started) heartbeat producer: the
/// commands send no boot-up message and no heartbeat.
const MASTER_NODE: NodeId = match NodeId::new(127) {
    Some(n) => n,
    None => panic!("127 is a node id"),
};

/// Any bus: SocketCAN, or the virtual bus in tests.
pub struct LiveBus {
    inner: Box<dyn Bus + Send>,
}

impl LiveBus {
    pub fn new(inner: Box<dyn Bus + Send>) -> LiveBus {
        LiveBus { inner }
    }

    /// Opens SocketCAN interface `iface` ([`open_socketcan`]).
    pub fn open(iface: &str) -> Result<LiveBus, LiveError> {
        open_socketcan(iface)
            .map(LiveBus::new)
            .map_err(LiveError::Failed)
    }
}

impl Bus for LiveBus {
    fn send(&mut self, frame: &Frame) -> io::Result<()> {
        self.inner.send(frame)
    }

    fn recv(&mut self, timeout: Duration) -> io::Result<Option<Frame>> {
        self.inner.recv(timeout)
    }
}

/// Opens SocketCAN interface `iface` for every command that uses a bus;
/// the error names the interface, says why and what to do (no such
/// interface, not a CAN one, down, no SocketCAN in the kernel).
pub fn open_socketcan(iface: &str) -> Result<Box<dyn Bus + Send>, String> {
    #[cfg(target_os = "linux")]
    {
        use eds2rust_runtime::transport::socketcan::SocketCanBus;
        let sys = std::path::Path::new("/sys/class/net").join(iface);
        let bus = SocketCanBus::open(iface).map_err(|e| open_failed(iface, &sys, &e))?;
        // IFF_UP: a socket binds to a down interface, sending fails.
        let flags = std::fs::read_to_string(sys.join("flags")).unwrap_or_default();
        let flags = u32::from_str_radix(flags.trim().trim_start_matches("0x"), 16).unwrap_or(1);
        if flags & 1 == 0 {
            return Err(format!(
                "{iface}: the interface is down; bring it up with `ip link set up {iface}` \
                 (a CAN adapter also needs its bit rate: \
                 `ip link set {iface} type can bitrate 250000`)"
            ));
        }
        Ok(Box::new(bus))
    }
    #[cfg(not(target_os = "linux"))]
    {
        Err(format!(
            "{iface}: cannot open a CAN interface: SocketCAN needs Linux"
        ))
    }
}

#[cfg(target_os = "linux")]
fn open_failed(iface: &str, sys: &std::path::Path, e: &io::Error) -> String {
    let no_socketcan = !std::path::Path::new("/proc/net/can").exists();
    if !sys.exists() {
        let kernel = if no_socketcan {
            " (this kernel has no SocketCAN loaded: `modprobe can-raw vcan` first)"
        } else {
            ""
        };
        return format!(
            "{iface}: no such CAN interface; create one with \
             `ip link add dev {iface} type vcan && ip link set up {iface}`{kernel} ({e})"
        );
    }
    // ARPHRD_CAN: CAN adapters and vcan.
    let link_type = std::fs::read_to_string(sys.join("type")).unwrap_or_default();
    if !link_type.trim().is_empty() && link_type.trim() != "280" {
        return format!(
            "{iface}: not a CAN interface (link type {}); `ip link show type vcan` and \
             `ip -details link show` list the CAN ones ({e})",
            link_type.trim()
        );
    }
    if no_socketcan {
        return format!(
            "{iface}: this kernel has no SocketCAN; load it with `modprobe can-raw` ({e})"
        );
    }
    format!("{iface}: cannot open the CAN interface: {e}")
}

/// A master on `bus` that sends nothing of its own (no boot-up, no
/// heartbeat): only the commands' requests.
pub fn master(bus: LiveBus) -> Master<LiveBus> {
    Master::new(bus, master::Master::new(MASTER_NODE, None))
}

/// What a command opens its bus with: called once, after the command line
/// and the files have been checked.
pub trait Opener: FnOnce() -> Result<LiveBus, LiveError> {}

impl<F: FnOnce() -> Result<LiveBus, LiveError>> Opener for F {}

/// A [`master`] on `bus` with an SDO client for `node` ([`sdo_client`]).
pub fn sdo_master(bus: LiveBus, node: NodeId, timeout: Duration) -> Master<LiveBus> {
    let mut m = master(bus);
    sdo_client(&mut m, node, timeout);
    m
}

/// Gives `node` an SDO client on its default channel with `timeout` per
/// step.
pub fn sdo_client(m: &mut Master<LiveBus>, node: NodeId, timeout: Duration) {
    let mut config = ClientConfig::new(Channel::default_for(node));
    config.timeout = timeout;
    m.core_mut().add_sdo_client(node, config);
}

/// A node id 1 to 127.
pub fn node_id(n: u8) -> Result<NodeId, LiveError> {
    NodeId::new(n).ok_or_else(|| LiveError::Usage(format!("{n} is not a node id (1 to 127)")))
}

/// A progress bar of `len` units on stderr, hidden when stdout is not a
/// terminal (a pipe, a file, a test).
pub fn bar(len: u64, bytes: bool) -> ProgressBar {
    bar_drawn(len, bytes, std::io::stdout().is_terminal())
}

/// [`bar`], drawn on stderr only when `terminal`.
fn bar_drawn(len: u64, bytes: bool, terminal: bool) -> ProgressBar {
    let target = if terminal {
        ProgressDrawTarget::stderr()
    } else {
        ProgressDrawTarget::hidden()
    };
    let bar = ProgressBar::with_draw_target(Some(len), target);
    let template = if bytes {
        "{msg} [{bar:40}] {bytes}/{total_bytes} {bytes_per_sec} eta {eta}"
    } else {
        "{msg} [{bar:40}] {pos}/{len} eta {eta}"
    };
    if let Ok(style) = ProgressStyle::with_template(template) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Off when stdout is not a terminal, whatever stderr is. (Drawing on
    /// a terminal needs one: indicatif hides a bar on a stderr that is not.)
    #[test]
    fn the_bar_is_off_when_stdout_is_not_a_terminal() {
        assert!(bar_drawn(10, true, false).is_hidden());
        assert!(bar_drawn(10, false, false).is_hidden());
    }
}
