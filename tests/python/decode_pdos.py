"""python-canopen's decoding of the default PDOs of EDS/DCF files, as JSON.

Usage: python decode_pdos.py SPEC.json

SPEC.json: {"frames": K, "files": [{"eds": path, "node_id": n}, ...]}.

The oracle of tests/tests/decode_corpus.rs. Each file is loaded into a
RemoteNode (node id n) on a canopen.Network that is never connected, and
every TPDO and RPDO map python-canopen finds is read from the object
dictionary (`read(from_od=True)`: the DCF's ParameterValue, else the
DefaultValue, with $NODEID resolved). Per map the line holds its COB-ID,
whether it is valid, the mapped variables (name, index, subindex, bit
offset and length) and, for a valid map, K frames of the map's data length
(the bits its entries give, at most 8 bytes) with the `.raw` of every
variable after `map.on_message(cob_id, data, 0.0)` (what a user does on
reception). The frames are the data all zero, all ones, then pseudo-random
bytes seeded by file, PDO and frame number, so that they are the same on
every run; the test sends the same bytes to eds2rust's decoder.

Values are tagged so that JSON carries them exactly: {"int": v} (BOOLEAN as
0/1 with "bool": true), {"real": hex} (the IEEE 754 double python-canopen
returns, big-endian hex, so NaN and -0.0 survive), {"text": s}, {"hex": s}
for bytes, {"error": message} when python-canopen raises.

Failures are data, never a crash: a file that does not load gives "error";
a map whose read raises gives its "error". A transmission type without a
DefaultValue makes read(from_od=True) raise TypeError (it compares None
with 254); as in bench_pdo.py it is set to 255 first and a note says so.
"""

import json
import logging
import math
import random
import struct
import sys
from importlib.metadata import version

import canopen

# Collects the warnings python-canopen logs (e.g. a mapped entry it lacks).
from od_dump import Collect


def tagged(value):
    """A `.raw` value as a tagged JSON object."""
    if isinstance(value, bool):
        return {"int": int(value), "bool": True}
    if isinstance(value, int):
        return {"int": value}
    if isinstance(value, float):
        return {"real": struct.pack(">d", value).hex()}
    if isinstance(value, str):
        return {"text": value}
    if isinstance(value, (bytes, bytearray)):
        return {"hex": bytes(value).hex()}
    return {"error": f"unexpected value {value!r}"}


def frames_for(path, kind, number, nbytes, count):
    """`count` deterministic frames of `nbytes` bytes."""
    frames = [bytes(nbytes), bytes([0xFF] * nbytes)]
    for i in range(max(0, count - 2)):
        # A str seed is hashed with SHA-512: the same bytes on every run and platform.
        rng = random.Random(f"{path}|{kind}{number}|{i}")
        frames.append(bytes(rng.getrandbits(8) for _ in range(nbytes)))
    return frames[:count]


def variable(var):
    return {
        "name": var.name,
        "index": var.index,
        "subindex": var.subindex,
        "offset": var.offset,
        "length": var.length,
        "data_type": var.od.data_type,
    }


def declared_bits(pdo_map):
    """The bits the mapping entries give (index and length not zero), as
    read() reads them; more than `map.length` when python-canopen dropped a
    variable the object dictionary lacks (it drops its bits too)."""
    def value(param):
        return param.od.value if param.od.value is not None else param.od.default

    bits = 0
    for subindex in range(1, value(pdo_map.map_array[0]) + 1):
        entry = value(pdo_map.map_array[subindex])
        if entry >> 16 and entry & 0x7F:
            bits += entry & 0x7F
    return bits


def decode(pdo_map, data):
    """The `.raw` of every mapped variable after receiving `data`."""
    # python-can hands on_message a bytearray.
    pdo_map.on_message(pdo_map.cob_id, bytearray(data), 0.0)
    values = []
    for var in pdo_map.map:
        try:
            values.append(tagged(var.raw))
        except Exception as exc:  # the oracle reports every failure as data
            values.append({"error": f"{type(exc).__name__}: {exc}"})
    return values


def read_map(path, kind, number, pdo_map, frame_count):
    collect = Collect()
    logger = logging.getLogger("canopen")
    logger.addHandler(collect)
    result = {"kind": kind, "number": number, "error": None, "notes": []}
    try:
        try:
            trans_type = pdo_map.com_record[2].od
            if trans_type.default is None and trans_type.value is None:
                trans_type.default = 255
                result["notes"].append("transmission type has no DefaultValue; set to 255 "
                                       "so that read(from_od=True) works")
        except KeyError:
            pass  # read() reports the missing entry itself
        raw_cob = pdo_map.com_record[1].od
        raw_cob = raw_cob.value if raw_cob.value is not None else raw_cob.default
        pdo_map.read(from_od=True)
    except Exception as exc:  # the oracle reports every failure as data
        result["error"] = f"{type(exc).__name__}: {exc}"
        result["warnings"] = collect.messages
        logger.removeHandler(collect)
        return result
    result.update({
        "cob_id_entry": raw_cob,
        "cob_id": pdo_map.cob_id,
        "enabled": pdo_map.enabled,
        "length": pdo_map.length,
        "declared_bits": declared_bits(pdo_map),
        "variables": [variable(v) for v in pdo_map.map],
        "frames": [],
    })
    if pdo_map.enabled:
        bits = max(pdo_map.length, result["declared_bits"])
        nbytes = min(8, math.ceil(bits / 8))
        for data in frames_for(path, kind, number, nbytes, frame_count):
            result["frames"].append({"data": data.hex(), "raw": decode(pdo_map, data)})
    logger.removeHandler(collect)
    result["warnings"] = collect.messages
    return result


def read_file(entry, frame_count):
    path, node_id = entry["eds"], entry["node_id"]
    out = {"eds": path, "node_id": node_id, "error": None, "pdos": []}
    collect = Collect()
    logger = logging.getLogger("canopen")
    logger.addHandler(collect)
    try:
        network = canopen.Network()  # never connected: nothing is sent
        node = canopen.RemoteNode(node_id, path)
        network.add_node(node)
    except Exception as exc:  # the oracle reports every failure as data
        out["error"] = f"{type(exc).__name__}: {exc}"
        return out
    finally:
        logger.removeHandler(collect)
    for kind, pdos in (("tpdo", node.tpdo), ("rpdo", node.rpdo)):
        for number, pdo_map in sorted(pdos.map.items()):
            out["pdos"].append(read_map(path, kind, number, pdo_map, frame_count))
    return out


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    # Only the Collect handlers see the log records; nothing goes to stderr.
    logging.getLogger("canopen").propagate = False
    logging.getLogger("canopen").setLevel(logging.WARNING)
    with open(sys.argv[1], encoding="utf-8") as f:
        spec = json.load(f)
    files = [read_file(entry, spec["frames"]) for entry in spec["files"]]
    print(json.dumps({"canopen": version("canopen"), "files": files}))


if __name__ == "__main__":
    main()
