//! Lowers a parsed [`Table`] into an [`ir::Device`] in the documented order:
//! base → delete → modify → add → semantics → PDO defaults → error tables,
//! variants and the checks across the device.
//!
//! The base is the table's own `base:` EDS, or a device the caller gives
//! ([`Base::Given`], an overlay passed to the builder); the stages after it
//! are the same for both.

use std::path::{Path, PathBuf};

use serde_saphyr::Spanned;

use super::schema::Table;
use super::{At, Base, Ctx};
use crate::ir::{Device, ProfileChoice};

/// Lowers `table`; every file read on the way (a `base:` EDS) is appended
/// to `files`.
pub(super) fn lower(ctx: &mut Ctx, table: &Table, base: Base, files: &mut Vec<PathBuf>) -> Device {
    if table.format.value != 1 {
        ctx.error(
            "table::format",
            At::of(&table.format),
            "",
            "format",
            format!(
                "format {} is not known; this reader reads format 1",
                table.format.value
            ),
        );
    }
    let has_base = table.base.is_some() || matches!(base, Base::Given(_));
    let mut device = match (base, &table.base) {
        (Base::Key(base_dir, options), Some(key)) => {
            match read_base(ctx, key, base_dir, options, files) {
                Some(device) => device,
                // Every later stage would only repeat that the base is missing.
                None => return Device::default(),
            }
        }
        (Base::Key(..), None) => whole_device_start(ctx, table),
        (Base::Given(device), key) => {
            if let Some(key) = key {
                ctx.error(
                    "table::overlay-base",
                    At::of(key),
                    "",
                    "base",
                    format!(
                        "this overlay is applied on the device it is given for; \
                         it must not name a base of its own (`{}` is not read)",
                        key.value
                    ),
                );
            }
            *device
        }
    };
    // What the base's mappings got wrong was reported with the base.
    let base_problems = if has_base {
        super::pdo::mapping_problems(&device)
    } else {
        Default::default()
    };
    if let Some(def) = &table.device {
        super::extra::apply_identity(ctx, &mut device.identity, def, true);
        if let Some(description) = &def.value.description {
            device.file_info.description = Some(description.value.clone());
        }
    }
    if let Some(network) = &table.network {
        super::extra::network(ctx, &mut device, network);
    }
    device
        .comments
        .extend(table.notes.iter().map(|n| n.value.clone()));

    // 2. delete, 3. modify: only for overlays.
    let overlay_only = [
        ("delete", table.delete.first().map(At::of)),
        ("modify", table.modify.first().map(At::of)),
    ];
    if !has_base {
        for (key, at) in overlay_only {
            if let Some(at) = at {
                ctx.error(
                    "table::overlay-only",
                    at,
                    "",
                    key,
                    format!("`{key}` changes a base EDS; this table has no `base:`"),
                );
            }
        }
    } else {
        let mut emptied_by = None;
        for def in &table.delete {
            let had_objects = !device.objects.is_empty();
            super::entry::delete(ctx, &mut device, def);
            if had_objects && device.objects.is_empty() {
                emptied_by = Some(def);
            }
        }
        if let Some(def) = emptied_by
            && table.objects.is_empty()
        {
            ctx.error(
                "table::no-objects",
                At::of(def),
                "delete",
                "",
                "this `delete` removes the last object of the base, and the table adds none: \
                 a device needs at least one object (no reader accepts an EDS without one)"
                    .into(),
            );
        }
        for def in &table.modify {
            super::entry::modify(ctx, &mut device, def);
        }
    }
    // 4. add (with inline semantics), 5. the semantics list.
    for def in &table.objects {
        super::entry::add(ctx, &mut device, def);
    }
    for def in &table.semantics {
        super::meaning::apply_list_item(ctx, &mut device, def);
    }
    // 6. PDO defaults.
    super::pdo::apply(ctx, &mut device, &table.pdos);
    // 7. error tables, variants, checks across the device.
    super::extra::error_tables(ctx, &mut device, &table.errors);
    super::extra::variants(ctx, &mut device, &table.variants);
    super::meaning::check_error_table_references(ctx, &device);
    let written = super::pdo::written_mappings(&table.pdos);
    let changes = changed_objects(table);
    super::pdo::check_mappings(ctx, &device, &written, &base_problems, &changes);
    device.fill_identity_from_1018();
    if let Some(choice) = &table.profiles {
        match choice.value.as_str() {
            "none" => device.profiles = ProfileChoice::None,
            "builtin" => device.profiles = ProfileChoice::Builtin,
            other => ctx.error(
                "table::bad-profiles",
                At::of(choice),
                "",
                "profiles",
                format!("`profiles: {other}` is not known; write `none` (no built-in meanings of the standard objects) or `builtin` (the default)"),
            ),
        }
    }
    device
}

/// Where the table deletes, modifies or adds each object it touches (the
/// first such place), by index.
fn changed_objects(table: &Table) -> std::collections::BTreeMap<u16, At> {
    let mut out = std::collections::BTreeMap::new();
    for def in table
        .delete
        .iter()
        .chain(&table.modify)
        .chain(&table.objects)
    {
        if let Some(index) = &def.value.index {
            out.entry(index.value).or_insert_with(|| At::of(def));
        }
    }
    out
}

fn read_base(
    ctx: &mut Ctx,
    base: &Spanned<String>,
    base_dir: &Path,
    options: &crate::read::Options,
    files: &mut Vec<PathBuf>,
) -> Option<Device> {
    let path = base_dir.join(&base.value);
    let inside = crate::bounded::check_base(
        &path,
        options.project_dir.as_deref(),
        &options.allow_base_dirs,
    );
    if let Err(message) = inside {
        ctx.error("table::base-outside", At::of(base), "", "base", message);
        ctx.note(
            "allow a directory with `--allow-base-dir DIR` (command line), \
             `Builder::allow_base_dir` (build script) or `Options::allow_base_dirs` (library)"
                .into(),
        );
        return None;
    }
    let loaded = crate::eds::read_file_unfinished(&path, options);
    files.extend(loaded.files);
    let failed = loaded.diagnostics.has_errors();
    ctx.diags.extend(loaded.diagnostics);
    match loaded.device {
        Some(device) if !failed => Some(device),
        _ => {
            ctx.error(
                "table::base",
                At::of(base),
                "",
                "base",
                format!(
                    "the base EDS `{}` could not be read without errors (see above)",
                    path.display()
                ),
            );
            None
        }
    }
}

fn whole_device_start(ctx: &mut Ctx, table: &Table) -> Device {
    let mut device = Device {
        source: ctx.file.to_string(),
        ..Device::default()
    };
    device.file_info.file_name = Path::new(ctx.file)
        .file_name()
        .map(|n| n.to_string_lossy().into_owned());
    device.file_info.created_by = Some("eds2rust YAML object table".into());
    let at = At::of(&table.format);
    match &table.device {
        None => ctx.error(
            "table::missing-key",
            at,
            "",
            "device",
            "a whole-device table needs `device:` with at least vendor_name and product_name"
                .into(),
        ),
        Some(def) => {
            for (key, value) in [
                ("vendor_name", &def.value.vendor_name),
                ("product_name", &def.value.product_name),
            ] {
                if value.is_none() {
                    ctx.error(
                        "table::missing-key",
                        At::of(def),
                        "device",
                        key,
                        format!("a whole-device table needs `device.{key}`"),
                    );
                }
            }
        }
    }
    if table.objects.is_empty() {
        ctx.error(
            "table::missing-key",
            at,
            "",
            "objects",
            "a whole-device table needs `objects:` with at least one object".into(),
        );
    }
    device
}
