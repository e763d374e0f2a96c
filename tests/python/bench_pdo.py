"""Time python-canopen's PDO maps decoding and encoding given frames.

Usage: python bench_pdo.py --batches N SPEC.json

SPEC.json: {"pdos": [{"eds": path, "node_id": n, "kind": "tpdo"|"rpdo",
"number": n, "frames": [[byte, ...], ...]}, ...], "min_batch_ops": n}.

Each device's EDS is loaded into a RemoteNode on a canopen.Network that is
never connected; the PDO maps are read from the object dictionary
(`read(from_od=True)`). Per frame, decoding is what a user does on reception:
`map.on_message(cob_id, data, timestamp)`, then `.raw` of every mapped
variable; encoding sets `.raw` of every mapped variable and takes
`bytes(map.data)`. Prints one JSON line: per PDO the median ns per frame of
each (over N batches of at least min_batch_ops frames, after a warm-up), the
raw values decoded from every frame and the bytes encoded back from them.
Logging is disabled (python-canopen warns when a written value is outside
the entry's limits). The anchor of eds2rust's pdo_codec benchmark.
"""

import argparse
import json
import logging
import platform
import statistics
import time
from importlib.metadata import version

import canopen


def load_maps(spec):
    """The PDO map of every spec entry, one RemoteNode per EDS file."""
    nodes, notes = {}, []
    maps = []
    for pdo in spec["pdos"]:
        key = (pdo["eds"], pdo["node_id"])
        if key not in nodes:
            network = canopen.Network()  # never connected: nothing is sent
            node = canopen.RemoteNode(pdo["node_id"], pdo["eds"])
            network.add_node(node)
            nodes[key] = node
        node = nodes[key]
        pdos = node.tpdo if pdo["kind"] == "tpdo" else node.rpdo
        pdo_map = pdos.map[pdo["number"]]
        trans_type = pdo_map.com_record[2].od
        if trans_type.default is None and trans_type.value is None:
            # read(from_od=True) compares the transmission type with 254 and
            # raises TypeError when the EDS gives it no DefaultValue.
            trans_type.default = 255
            notes.append(f"{pdo['eds']}: {pdo['kind']}{pdo['number']} transmission type has "
                         "no DefaultValue; set to 255 so that read(from_od=True) works")
        pdo_map.read(from_od=True)
        maps.append(pdo_map)
    return maps, notes


def decode(pdo_map, frame):
    pdo_map.on_message(pdo_map.cob_id, frame, 0.0)
    return [var.raw for var in pdo_map.map]


def encode(pdo_map, raws):
    for var, raw in zip(pdo_map.map, raws):
        var.raw = raw
    return bytes(pdo_map.data)


def median_ns(batches, passes, frames_per_pass, run):
    """Median ns per frame of `run(passes)` over `batches` runs, after a warm-up pass."""
    run(1)
    samples = []
    for _ in range(batches):
        start = time.perf_counter_ns()
        run(passes)
        samples.append((time.perf_counter_ns() - start) / (passes * frames_per_pass))
    return statistics.median(samples)


def bench(pdo_map, frames, batches, min_batch_ops):
    frames = [bytearray(f) for f in frames]  # python-can hands on_message a bytearray
    raws = [decode(pdo_map, f) for f in frames]
    pdo_map.data = bytearray(len(frames[0]))
    encoded = [list(encode(pdo_map, r)) for r in raws]
    passes = max(1, -(-min_batch_ops // len(frames)))

    def run_decode(n):
        for _ in range(n):
            for frame in frames:
                decode(pdo_map, frame)

    def run_encode(n):
        for _ in range(n):
            for values in raws:
                encode(pdo_map, values)

    return {"decode_ns": median_ns(batches, passes, len(frames), run_decode),
            "encode_ns": median_ns(batches, passes, len(frames), run_encode),
            "raw": raws, "encoded": encoded, "variables": [var.name for var in pdo_map.map]}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--batches", type=int, default=21)
    parser.add_argument("spec")
    args = parser.parse_args()
    # Setting .raw outside an entry's limits logs a warning per write (to stderr
    # by default), which the pseudo-random frames do often: not timed here.
    logging.disable(logging.CRITICAL)
    with open(args.spec, encoding="utf-8") as f:
        spec = json.load(f)
    maps, notes = load_maps(spec)
    results = [bench(m, p["frames"], args.batches, spec["min_batch_ops"])
               for m, p in zip(maps, spec["pdos"])]
    print(json.dumps({"python": platform.python_version(), "canopen": version("canopen"),
                      "batches": args.batches, "statistic": "median", "notes": notes,
                      "pdos": results}))


if __name__ == "__main__":
    main()
