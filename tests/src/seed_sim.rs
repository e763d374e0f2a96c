//! A seed device for python-canopen and its simulator: the seed table
//! exported to EDS (what python-canopen's `RemoteNode` reads), and a
//! simulator served in a thread on a bus port (the recorded session and
//! the interop tests).

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;

use eds2rust::eds::Options;
use eds2rust::r#gen::eds::to_eds;
use eds2rust_runtime::transport::{Bus, Clock};
use eds2rust_runtime::{Instant, Service, blocking};

/// The seed table `eds/<name>.yaml` exported to EDS under
/// `<target>/tmp/<scratch>/`, and its node id; a table with any
/// diagnostic is an error.
pub fn export_eds(name: &str, scratch: &str) -> Result<(PathBuf, u8), String> {
    let table = crate::workspace_root().join(format!("eds/{name}.yaml"));
    let loaded = eds2rust::input::read_device(&table, &Options::strict());
    if !loaded.diagnostics.is_empty() {
        return Err(loaded.diagnostics.render());
    }
    let device = loaded
        .device
        .ok_or_else(|| format!("{} does not load", table.display()))?;
    let node = device
        .network
        .node_id
        .ok_or_else(|| format!("{} has no node id", table.display()))?;
    let dir = crate::target_dir().join("tmp").join(scratch);
    std::fs::create_dir_all(&dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let path = dir.join(format!("{name}.eds"));
    // Written beside and renamed: parallel sessions never read half a file.
    let part = dir.join(format!("{name}.eds.{}", std::process::id()));
    std::fs::write(&part, to_eds(&device))
        .and_then(|()| std::fs::rename(&part, &path))
        .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    Ok((path, node))
}

/// A simulator served on a bus port in a thread (`blocking::serve`) until
/// [`Served::finish`] or drop; dropping it fails the test when the thread
/// panicked or the bus failed (unless the test is failing already).
pub struct Served {
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<std::io::Result<()>>>,
}

impl Served {
    /// The simulator `make` gives at the clock's now, served on `port`.
    pub fn start<P, S>(mut port: P, make: impl FnOnce(Instant) -> S) -> Served
    where
        P: Bus + Send + 'static,
        S: Service + Send + 'static,
    {
        let clock = Clock::new();
        let mut device = make(clock.now());
        let stop = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&stop);
        let thread = std::thread::spawn(move || {
            blocking::serve(&mut port, &clock, &mut device, &flag, None, |_| {})
        });
        Served {
            stop,
            thread: Some(thread),
        }
    }

    /// Stops the simulator: an error when its thread panicked or its bus
    /// failed.
    pub fn finish(mut self) -> Result<(), String> {
        self.stop.store(true, Ordering::Relaxed);
        match self.thread.take().map(JoinHandle::join) {
            Some(Ok(Ok(()))) | None => Ok(()),
            Some(Ok(Err(e))) => Err(format!("the simulator's bus failed: {e}")),
            Some(Err(_)) => Err("the simulator thread panicked".to_string()),
        }
    }
}

impl Drop for Served {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(thread) = self.thread.take() {
            let result = thread.join().expect("the simulator thread panicked");
            if !std::thread::panicking() {
                result.expect("the simulator's bus failed");
            }
        }
    }
}
