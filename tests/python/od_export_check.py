"""Load EDS/DCF files (eds2rust's EDS exports) with python-canopen, one JSON line per file.

Usage: python od_export_check.py --node-id 5 FILE [FILE...]

The oracle of tests/tests/export_eds.rs: each file is loaded with
canopen.import_od(path, node_id=N); the line holds whether it loaded, every
entry python-canopen models (od_dump.entries_of, in the schema of
`eds2rust dump --format json`) and every warning raised while loading:
log records of WARNING and above from any logger, and Python `warnings`.
"""

import logging
import warnings

import canopen

# The entries in the dump's JSON form, exactly as the differential test's oracle writes them.
from od_dump import entries_of, per_file_main


class Collect(logging.Handler):
    """Collects log records of WARNING and above while one file loads."""

    def __init__(self):
        super().__init__(level=logging.WARNING)
        self.messages = []

    def emit(self, record):
        self.messages.append(f"{record.levelname} {record.name}: {record.getMessage()}")


def load(path, node_id):
    collect = Collect()
    root = logging.getLogger()
    root.addHandler(collect)
    previous_level = root.level
    root.setLevel(logging.WARNING)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            od = canopen.import_od(path, node_id=node_id)
            error = None
        except Exception as exc:  # the oracle reports every failure as data
            od = None
            error = f"{type(exc).__name__}: {exc}"
        finally:
            root.removeHandler(collect)
            root.setLevel(previous_level)
    messages = collect.messages + [f"{w.category.__name__}: {w.message}" for w in caught]
    if od is None:
        return {"file": path, "ok": False, "error": error, "warnings": messages, "entries": []}
    entries = entries_of(od)
    return {"file": path, "ok": True, "error": None, "warnings": messages, "entries": entries}


if __name__ == "__main__":
    per_file_main(__doc__, load)
