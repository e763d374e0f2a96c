"""python-canopen on a SocketCAN interface, for tests/tests/vcan_python.rs.

Runs one flow against the Rust side over a real (v)can interface and prints
JSON lines on stdout. The command is a JSON object on argv[1] (or stdin):

  {"op": "sdo_server", "channel", "node", "objects": [{"index", "sub",
   "type", "value" (hex)}]}
      A LocalNode SDO server. Prints {"ready": true}, serves until stdin
      closes, then prints {"values": {"IIII:SS": hex}} for every object.
  {"op": "sdo_client", "channel", "node", "steps": [{"do": "upload" |
   "download", "index", "sub", "value" (hex), "block", "segmented"}]}
      A RemoteNode SDO client. Prints {"results": [hex or null]}.
  {"op": "nmt_master", "channel", "node", "states": [...], "timeout"}
      Waits for a PRE-OPERATIONAL heartbeat, then commands each state and
      waits for a heartbeat that reports it. Prints {"seen": [[state, ...]
      per step], "reached": [state per step]}.
  {"op": "tpdo", "channel", "node", "cob_id", "objects": [{"index",
   "type"}], "timeout"}
      A RemoteNode whose TPDO1 maps the objects (sub 0) in order. Prints
      {"ready": true}, waits for the PDO, prints {"data": hex, "values":
      [decoded value per object]}.

Any failure prints {"error": "..."} and exits with status 1.
"""

import json
import sys
import traceback

import canopen
from canopen.objectdictionary import ODRecord, ODVariable, ObjectDictionary, datatypes


def emit(obj):
    """Writes one JSON line and flushes it."""
    sys.stdout.write(json.dumps(obj) + "\n")
    sys.stdout.flush()


def connect(cmd):
    """A canopen Network on python-can's socketcan interface."""
    network = canopen.Network()
    network.connect(interface="socketcan", channel=cmd["channel"])
    return network


def sdo_server(cmd):
    network = connect(cmd)
    od = ObjectDictionary()
    for obj in cmd["objects"]:
        var = ODVariable("obj_%04X_%02X" % (obj["index"], obj["sub"]),
                         obj["index"], obj["sub"])
        var.data_type = getattr(datatypes, obj["type"])
        var.access_type = "rw"
        od.add_object(var)
    node = canopen.LocalNode(cmd["node"], od)
    for obj in cmd["objects"]:
        node.data_store.setdefault(obj["index"], {})[obj["sub"]] = \
            bytes.fromhex(obj["value"])
    network.add_node(node)
    emit({"ready": True})
    sys.stdin.read()
    values = {}
    for obj in cmd["objects"]:
        data = node.get_data(obj["index"], obj["sub"])
        values["%04X:%02X" % (obj["index"], obj["sub"])] = bytes(data).hex().upper()
    network.disconnect()
    return {"values": values}


def sdo_client(cmd):
    network = connect(cmd)
    node = network.add_node(cmd["node"], ObjectDictionary())
    sdo = node.sdo
    sdo.RESPONSE_TIMEOUT = 5.0
    results = []
    for step in cmd["steps"]:
        index, sub = step["index"], step["sub"]
        if step["do"] == "upload":
            if step.get("block"):
                with sdo.open(index, sub, "rb", block_transfer=True) as fp:
                    data = fp.read()
            else:
                data = sdo.upload(index, sub)
            results.append(bytes(data).hex().upper())
        else:
            data = bytes.fromhex(step["value"])
            if step.get("block"):
                with sdo.open(index, sub, "wb", size=len(data),
                              block_transfer=True) as fp:
                    fp.write(data)
            else:
                sdo.download(index, sub, data,
                             force_segment=step.get("segmented", False))
            results.append(None)
    network.disconnect()
    return {"results": results}


def nmt_master(cmd):
    network = connect(cmd)
    node = network.add_node(cmd["node"], ObjectDictionary())
    timeout = cmd.get("timeout", 5.0)

    def wait_for(state):
        seen = []
        while len(seen) < 20:
            seen.append(node.nmt.wait_for_heartbeat(timeout))
            if seen[-1] == state:
                break
        return seen

    emit({"ready": True})
    seen = [wait_for("PRE-OPERATIONAL")]
    for state in cmd["states"]:
        node.nmt.state = state
        seen.append(wait_for(state))
    network.disconnect()
    return {"seen": seen, "reached": [s[-1] for s in seen]}


def variable(name, index, sub, data_type):
    """An object dictionary variable of the given datatypes name."""
    var = ODVariable(name, index, sub)
    var.data_type = getattr(datatypes, data_type)
    var.access_type = "rw"
    return var


def tpdo(cmd):
    network = connect(cmd)
    od = ObjectDictionary()
    # TPDO1's communication and mapping records, so that tpdo[1] exists.
    com = ODRecord("tpdo1_com", 0x1800)
    for sub, kind in [(0, "UNSIGNED8"), (1, "UNSIGNED32"), (2, "UNSIGNED8")]:
        com.add_member(variable("com_%d" % sub, 0x1800, sub, kind))
    od.add_object(com)
    mapping = ODRecord("tpdo1_map", 0x1A00)
    mapping.add_member(variable("count", 0x1A00, 0, "UNSIGNED8"))
    for sub in range(1, 9):
        mapping.add_member(variable("map_%d" % sub, 0x1A00, sub, "UNSIGNED32"))
    od.add_object(mapping)
    for obj in cmd["objects"]:
        od.add_object(variable("obj_%04X" % obj["index"], obj["index"], 0, obj["type"]))
    node = network.add_node(cmd["node"], od)
    pdo = node.tpdo[1]
    pdo.clear()
    for obj in cmd["objects"]:
        pdo.add_variable(obj["index"])
    pdo.cob_id = cmd["cob_id"]
    pdo.enabled = True
    pdo.subscribe()
    emit({"ready": True})
    if pdo.wait_for_reception(cmd.get("timeout", 5.0)) is None:
        raise TimeoutError("no PDO on 0x%X" % cmd["cob_id"])
    result = {"data": bytes(pdo.data).hex().upper(),
              "values": [var.raw for var in pdo.map]}
    network.disconnect()
    return result


def main():
    text = sys.argv[1] if len(sys.argv) > 1 else sys.stdin.readline()
    try:
        cmd = json.loads(text)
        op = {"sdo_server": sdo_server, "sdo_client": sdo_client,
              "nmt_master": nmt_master, "tpdo": tpdo}[cmd["op"]]
        emit(op(cmd))
    except Exception as e:  # reported to the Rust test, which fails
        traceback.print_exc()
        emit({"error": "%s: %s" % (type(e).__name__, e)})
        sys.exit(1)


if __name__ == "__main__":
    main()
