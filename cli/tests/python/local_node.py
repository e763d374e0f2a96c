"""A python-canopen LocalNode on a SocketCAN interface, for the live-bus
tests of the CLI (cli/tests/live_vcan.rs).

argv[1] is a JSON object {"channel", "node", "eds", "data": {"IIII:SS": hex},
"report": ["IIII:SS", ...]}: the LocalNode serves the EDS at node id "node",
with "data" stored before it starts. It prints {"ready": true}, serves until
stdin closes, then prints {"values": {"IIII:SS": hex or null}} for every
entry of "report" (null: nothing stored and no default). Any failure prints
{"error": "..."} and exits with status 1.
"""

import json
import sys

import canopen

from json_lines import emit, run


def key(text):
    index, sub = text.split(":")
    return int(index, 16), int(sub, 16)


def main():
    cmd = json.loads(sys.argv[1])
    network = canopen.Network()
    network.connect(interface="socketcan", channel=cmd["channel"])
    node = canopen.LocalNode(cmd["node"], cmd["eds"])
    for text, value in cmd.get("data", {}).items():
        index, sub = key(text)
        node.data_store.setdefault(index, {})[sub] = bytes.fromhex(value)
    network.add_node(node)
    emit({"ready": True})
    sys.stdin.read()
    values = {}
    for text in cmd.get("report", []):
        index, sub = key(text)
        try:
            values[text] = bytes(node.get_data(index, sub)).hex().upper()
        except Exception:  # noqa: BLE001 - no data is a value here
            values[text] = None
    network.disconnect()
    emit({"values": values})


if __name__ == "__main__":
    run(main)
