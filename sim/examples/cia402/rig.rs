//! The two masters the example drives with, behind one small interface:
//! the blocking master's [`blocking::DriveHandle`] and the tokio master's
//! [`tokio::DriveHandle`] (its driver on a runtime of its own). The
//! scenario in `main.rs` is written once against [`Rig`]; each rig only
//! forwards to the runtime's drive helper.

use eds2rust_runtime::Instant;
use eds2rust_runtime::blocking;
use eds2rust_runtime::cia402::{Event, Request, SessionConfig, State};
use eds2rust_runtime::master;
use eds2rust_runtime::od::{NodeId, ObjectInfo};
use eds2rust_runtime::tokio as async_master;
use eds2rust_runtime::transport::Clock;
use eds2rust_runtime::transport::virtual_bus::VirtualPort;
use eds2rust_sim::harness::MasterPort;

/// What the scenario needs of a master driving one CiA 402 node.
pub trait Rig {
    /// "blocking master" or "tokio master".
    fn name(&self) -> &'static str;
    /// Runs one request of the drive helper to its end.
    fn request(&mut self, request: Request) -> Result<(), String>;
    /// The drive's events since the last call.
    fn take_events(&mut self) -> Vec<(Instant, Event)>;
    /// Reads (index, sub) of the node by SDO.
    fn upload(&mut self, index: u16, sub: u8) -> Result<Vec<u8>, String>;
    /// The master's time.
    fn now(&mut self) -> Instant;
    /// The state of the last statusword seen.
    fn state(&self) -> Option<State>;
}

/// A core master as node `me`, without heartbeat of its own.
pub fn core(me: NodeId) -> master::Master {
    master::Master::new(me, None)
}

/// The blocking master's drive handle.
pub struct BlockingRig<'a> {
    /// The handle (it borrows the master).
    pub drive: blocking::DriveHandle<'a, MasterPort>,
}

impl BlockingRig<'_> {
    /// The handle of `master` for `node`, whose table is `objects`.
    pub fn new<'a>(
        master: &'a mut blocking::Master<MasterPort>,
        node: NodeId,
        objects: &'static [ObjectInfo],
        config: SessionConfig,
    ) -> Result<BlockingRig<'a>, String> {
        let drive = master
            .drive(node, objects, config)
            .map_err(|e| e.to_string())?;
        Ok(BlockingRig { drive })
    }
}

impl Rig for BlockingRig<'_> {
    fn name(&self) -> &'static str {
        "blocking master"
    }

    fn request(&mut self, request: Request) -> Result<(), String> {
        self.drive.request(request).map_err(|e| e.to_string())
    }

    fn take_events(&mut self) -> Vec<(Instant, Event)> {
        self.drive.take_events()
    }

    fn upload(&mut self, index: u16, sub: u8) -> Result<Vec<u8>, String> {
        let node = self.drive.node();
        self.drive
            .master()
            .upload(node, index, sub)
            .map_err(|e| e.to_string())
    }

    fn now(&mut self) -> Instant {
        self.drive.master().now()
    }

    fn state(&self) -> Option<State> {
        self.drive.state()
    }
}

/// The tokio master's drive handle, with the runtime its driver runs on
/// (one worker thread, so that the cores keep running between calls, as
/// in an async application).
pub struct TokioRig {
    runtime: tokio::runtime::Runtime,
    drive: Option<async_master::DriveHandle>,
    driver: Option<tokio::task::JoinHandle<std::io::Result<()>>>,
}

impl TokioRig {
    /// A tokio master on `port` (sharing the simulator's `clock`), its
    /// driver spawned, and the drive handle for `node`.
    pub fn new(
        port: VirtualPort,
        clock: Clock,
        me: NodeId,
        node: NodeId,
        objects: &'static [ObjectInfo],
        config: SessionConfig,
    ) -> Result<TokioRig, String> {
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(1)
            .enable_time()
            .build()
            .map_err(|e| format!("starting the tokio runtime: {e}"))?;
        let (master, driver) = {
            let _entered = runtime.enter();
            async_master::Master::with_clock(port, core(me), clock)
        };
        let driver = runtime.spawn(driver.run());
        let drive = master
            .drive(node, objects, config)
            .map_err(|e| e.to_string())?;
        Ok(TokioRig {
            runtime,
            drive: Some(drive),
            driver: Some(driver),
        })
    }

    fn handle(&mut self) -> &mut async_master::DriveHandle {
        self.drive.as_mut().expect("the handle lives until drop")
    }

    /// Drops the handle (the last master handle), so that the driver
    /// sends what it has and ends; its bus error, if any.
    pub fn finish(mut self) -> Result<(), String> {
        self.drive = None;
        match self.driver.take() {
            Some(driver) => match self.runtime.block_on(driver) {
                Ok(Ok(())) => Ok(()),
                Ok(Err(e)) => Err(format!("the tokio master's driver: {e}")),
                Err(e) => Err(format!("the tokio master's driver task: {e}")),
            },
            None => Ok(()),
        }
    }
}

impl Rig for TokioRig {
    fn name(&self) -> &'static str {
        "tokio master"
    }

    fn request(&mut self, request: Request) -> Result<(), String> {
        let runtime = self.runtime.handle().clone();
        let drive = self.handle();
        runtime
            .block_on(drive.request(request))
            .map_err(|e| e.to_string())
    }

    fn take_events(&mut self) -> Vec<(Instant, Event)> {
        self.handle().take_events()
    }

    fn upload(&mut self, index: u16, sub: u8) -> Result<Vec<u8>, String> {
        let runtime = self.runtime.handle().clone();
        let drive = self.handle();
        let (master, node) = (drive.master().clone(), drive.node());
        runtime
            .block_on(master.upload(node, index, sub))
            .map_err(|e| e.to_string())
    }

    fn now(&mut self) -> Instant {
        self.handle().master().now()
    }

    fn state(&self) -> Option<State> {
        self.drive
            .as_ref()
            .and_then(async_master::DriveHandle::state)
    }
}
