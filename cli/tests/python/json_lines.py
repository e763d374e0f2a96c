"""What the CLI tests' python-canopen scripts share: one JSON object a
line on stdout, and a main that reports any failure as {"error": "..."}
(with the traceback on stderr) and exits with status 1."""

import json
import sys
import traceback


def emit(obj):
    """Writes one JSON line and flushes it."""
    sys.stdout.write(json.dumps(obj) + "\n")
    sys.stdout.flush()


def run(main):
    """Runs `main`; a failure is reported to the Rust side, which fails."""
    try:
        main()
    except Exception as e:  # noqa: BLE001 - reported to the Rust side
        traceback.print_exc()
        emit({"error": "%s: %s" % (type(e).__name__, e)})
        sys.exit(1)
