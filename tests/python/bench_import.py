"""Time python-canopen's import_od over a set of EDS/DCF files.

Usage: python bench_import.py --iterations N FILE [FILE...]

Prints one JSON line: files, iterations, and the median seconds of one pass
over all files (after one warm-up pass). The anchor of eds2rust's read_corpus
benchmark.
"""

import argparse
import json
import logging
import statistics
import time

import canopen


def one_pass(files):
    for path in files:
        canopen.import_od(path, node_id=5)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--iterations", type=int, default=5)
    parser.add_argument("files", nargs="+")
    args = parser.parse_args()
    logging.disable(logging.CRITICAL)  # python-canopen warns on some files; not timed output
    loadable = []
    for path in args.files:  # files python-canopen cannot load are left out of both passes
        try:
            canopen.import_od(path, node_id=5)
            loadable.append(path)
        except Exception:
            pass
    samples = []
    for _ in range(args.iterations):
        start = time.perf_counter()
        one_pass(loadable)
        samples.append(time.perf_counter() - start)
    skipped = [path for path in args.files if path not in loadable]
    print(json.dumps({"files": len(loadable), "skipped": skipped, "iterations": args.iterations,
                      "seconds_per_pass": statistics.median(samples), "statistic": "median"}))


if __name__ == "__main__":
    main()
