"""python-canopen as the master of `eds2rust sim` on a SocketCAN interface,
for cli/tests/sim_vcan.rs.

argv[1] is a JSON object {"channel", "node", "rw": [index, sub, hex]}. The
script, with a RemoteNode on an empty object dictionary (raw SDO):
reads 0x1000 and 0x1018 sub 0..3 (expedited) and 0x1018 sub 1 again by
block upload; writes "rw" by a segmented download and reads it back by
block upload; writes 0x1017 = 100 ms (expedited) and reads it back; waits
for the heartbeat, starts the node and waits for "OPERATIONAL"; writes the
controlword 0x6040 = 0x06, 0x07, 0x0F, after each reading the statusword
0x6041 until bits 0-3, 5 and 6 show the next state (3 s at most).

It prints one JSON object: {"values": {"IIII:SS": hex}, "heartbeats":
[state, ...], "statuswords": [int, ...]}, or {"error": "..."} with exit
status 1.
"""

import json
import struct
import sys
import time

import canopen

from json_lines import emit, run
from canopen.objectdictionary import ObjectDictionary

# Controlword, then the statusword bits 0-3, 5, 6 of the state it leads to
# (CiA 402: Ready to switch on, Switched on, Operation enabled).
ENABLE = [(0x06, 0x21), (0x07, 0x23), (0x0F, 0x27)]
STATE_MASK = 0x6F


def main():
    cmd = json.loads(sys.argv[1])
    network = canopen.Network()
    network.connect(interface="socketcan", channel=cmd["channel"])
    node = network.add_node(cmd["node"], ObjectDictionary())
    sdo = node.sdo
    # Under the VM's emulated CPU the simulator answers slowly.
    sdo.RESPONSE_TIMEOUT = 5.0
    values = {}

    def upload(index, sub, block=False):
        if block:
            with sdo.open(index, sub, "rb", block_transfer=True) as fp:
                data = fp.read()
        else:
            data = sdo.upload(index, sub)
        return bytes(data).hex().upper()

    values["1000:00"] = upload(0x1000, 0)
    for sub in range(4):
        values["1018:%02X" % sub] = upload(0x1018, sub)
    values["1018:01 block"] = upload(0x1018, 1, block=True)

    index, sub, value = cmd["rw"]
    sdo.download(index, sub, bytes.fromhex(value), force_segment=True)
    values["%04X:%02X" % (index, sub)] = upload(index, sub, block=True)

    sdo.download(0x1017, 0, struct.pack("<H", 100))
    values["1017:00"] = upload(0x1017, 0)

    heartbeats = [node.nmt.wait_for_heartbeat(5.0)]
    node.nmt.state = "OPERATIONAL"
    for _ in range(20):
        heartbeats.append(node.nmt.wait_for_heartbeat(5.0))
        if heartbeats[-1] == "OPERATIONAL":
            break

    statuswords = []
    for controlword, want in ENABLE:
        sdo.download(0x6040, 0, struct.pack("<H", controlword))
        deadline = time.monotonic() + 3.0
        while True:
            (sw,) = struct.unpack("<H", bytes(sdo.upload(0x6041, 0))[:2])
            if sw & STATE_MASK == want or time.monotonic() > deadline:
                break
            time.sleep(0.02)
        statuswords.append(sw)

    network.disconnect()
    emit({"values": values, "heartbeats": heartbeats, "statuswords": statuswords})


if __name__ == "__main__":
    run(main)
