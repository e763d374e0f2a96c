//! A seed device for python-canopen: the seed table exported to EDS (what
//! python-canopen's `RemoteNode` reads; the recorded session and the
//! interop tests).

use std::path::PathBuf;

use eds2rust::eds::Options;
use eds2rust::r#gen::eds::to_eds;

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
