"""Dump python-canopen's view of EDS/DCF files as JSON, one line per file.

Usage: python od_dump.py --node-id 5 FILE [FILE...]

This is the independent oracle of eds2rust's differential test: each file is
loaded with canopen.import_od(path, node_id=N) and every entry python-canopen
models is printed in the schema of `eds2rust dump --format json`, plus the
raw default text and the warnings python-canopen logged while loading.
"""

import argparse
import json
import logging
import sys

import canopen
from canopen.objectdictionary import ODArray, ODRecord, ODVariable


class Collect(logging.Handler):
    """Collects warnings that python-canopen logs while loading one file."""

    def __init__(self):
        super().__init__(level=logging.WARNING)
        self.messages = []

    def emit(self, record):
        self.messages.append(record.getMessage())


def value(v):
    """A python-canopen value in the dump's JSON form."""
    if v is None:
        return None
    if isinstance(v, (bytes, bytearray)):
        return {"hex": bytes(v).hex()}
    if isinstance(v, bool):
        return int(v)
    if isinstance(v, float) and (v != v or v in (float("inf"), float("-inf"))):
        return None  # JSON has no NaN or infinity; eds2rust's dump writes null too
    return v


def entry(var, object_type, parent_name):
    return {
        "index": var.index,
        "subindex": var.subindex,
        "object_type": object_type,
        "parent_name": parent_name,
        "name": var.name,
        "data_type": var.data_type,
        "access": var.access_type,
        "pdo_mappable": bool(var.pdo_mappable),
        "default": value(var.default),
        "low_limit": value(var.min),
        "high_limit": value(var.max),
        "parameter_value": value(var.value),
        "node_relative": bool(var.relative),
        "default_raw": getattr(var, "default_raw", None),
    }


def entries_of(od):
    """Every entry python-canopen models, sorted by index and subindex."""
    entries = []
    # od.indices holds each object once (od.names may hold it twice).
    for index in sorted(od.indices):
        obj = od.indices[index]
        if isinstance(obj, ODVariable):
            entries.append(entry(obj, "VAR", None))
        else:
            kind = "ARRAY" if isinstance(obj, ODArray) else "RECORD"
            for sub in sorted(obj.subindices):
                entries.append(entry(obj.subindices[sub], kind, obj.name))
    return entries


def dump(path, node_id):
    collect = Collect()
    logger = logging.getLogger("canopen")
    logger.addHandler(collect)
    try:
        od = canopen.import_od(path, node_id=node_id)
    except Exception as exc:  # the oracle reports every failure as data
        return {"file": path, "ok": False, "error": f"{type(exc).__name__}: {exc}",
                "warnings": collect.messages, "entries": []}
    finally:
        logger.removeHandler(collect)
    entries = entries_of(od)
    return {"file": path, "ok": True, "error": None, "warnings": collect.messages, "entries": entries}


def per_file_main(doc, one_file):
    """The command line of a per-file oracle: `--node-id N FILE...`, and
    `one_file(path, node_id)` printed as one JSON line per file; `doc` is
    the script's docstring (its first line is the description)."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--node-id", type=int, required=True)
    parser.add_argument("files", nargs="+")
    args = parser.parse_args()
    for path in args.files:
        sys.stdout.write(json.dumps(one_file(path, args.node_id)) + "\n")


if __name__ == "__main__":
    per_file_main(__doc__, dump)
