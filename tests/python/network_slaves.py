"""A network of python-canopen slaves on a SocketCAN interface, for
tests/tests/vcan_network.rs.

Each slave is a canopen.LocalNode built from a device file (EDS or DCF):
python-canopen answers SDO from its object dictionary. What a LocalNode
does not do by itself, this script adds, as CiA 301 asks of a slave:

- the boot-up message and Pre-operational at power-on and after an NMT
  reset (reset node: every value back to the file's; reset communication:
  0x1000-0x1FFF back to the file's), then the heartbeat of 0x1017;
- NMT start, stop and enter pre-operational, reported in the heartbeat;
- in Operational, the PDOs as the master configured them over SDO (read
  from the node's own 0x1400-0x1BFF entries when it is started): a
  received RPDO's fields are written into the node's dictionary, and a
  TPDO is sent on command (event-driven, 254/255) or on SYNC (1-240).

The command is a JSON object on argv[1]:
  {"channel": "vcan2", "nodes": [{"node": 2, "file": "/path/x.eds"}]}
("interface": python-can's interface, "socketcan" when absent.)

Lines on stdout, one JSON object each:
  {"ready": true}                         all nodes booted once
  {"node": N, "nmt": STATE}               every state change (boot-up, NMT)
  {"node": N, "rpdo": K, "values": {"IIII:SS": hex}}   an RPDO taken in
  {"node": N, "tpdo": K, "data": hex}     a TPDO sent
  {"node": N, "value": hex}               the reply to "read"
  {"error": "..."}                        a failure (exit status 1)

Commands on stdin, one JSON object a line (end of input ends the script):
  {"op": "set", "node": N, "values": {"IIII:SS": hex}}   store values
  {"op": "tpdo", "node": N, "number": K}                 send TPDO K now
  {"op": "read", "node": N, "index": I, "sub": S}         one stored value
"""

import json
import logging
import sys
import threading
import traceback

import canopen

logging.basicConfig(level=logging.WARNING, stream=sys.stderr)

_out = threading.Lock()

# NMT command specifiers (CiA 301).
START, STOP, ENTER_PREOP, RESET_NODE, RESET_COMM = 1, 2, 128, 129, 130
SYNC_ID = 0x80


def emit(obj):
    """Writes one JSON line and flushes it (from any thread)."""
    with _out:
        sys.stdout.write(json.dumps(obj) + "\n")
        sys.stdout.flush()


def key(index, sub):
    return "%04X:%02X" % (index, sub)


def u32(data):
    return int.from_bytes(bytes(data)[:4].ljust(4, b"\0"), "little")


class Slave:
    """One LocalNode with the slave behaviour it lacks."""

    def __init__(self, network, node_id, path):
        self.network = network
        self.node = canopen.LocalNode(node_id, path)
        network.add_node(self.node)
        # NMT commands are handled here (a LocalNode only records them).
        network.unsubscribe(0, self.node.nmt.on_command)
        self.rpdo_ids = []
        self.sync_counts = {}

    @property
    def id(self):
        return self.node.id

    def state(self):
        return self.node.nmt.state

    def power_on(self):
        """Boot-up message, then Pre-operational and the heartbeat."""
        self.node.nmt.stop_heartbeat()
        self.drop_rpdos()
        # State INITIALISING sends the boot-up message; the step to
        # PRE-OPERATIONAL starts the heartbeat of 0x1017.
        self.node.nmt.send_command(RESET_NODE)
        self.node.nmt.send_command(ENTER_PREOP)
        emit({"node": self.id, "nmt": self.state()})

    def on_nmt(self, cmd):
        if cmd == RESET_NODE:
            self.node.data_store.clear()
            self.power_on()
        elif cmd == RESET_COMM:
            for index in [i for i in self.node.data_store if 0x1000 <= i <= 0x1FFF]:
                del self.node.data_store[index]
            self.power_on()
        elif cmd in (START, STOP, ENTER_PREOP):
            before = self.state()
            self.node.nmt.send_command(cmd)
            if cmd == START and before != "OPERATIONAL":
                self.load_pdos()
            if self.state() != before:
                emit({"node": self.id, "nmt": self.state()})

    # ---------------------------------------------------------------- PDOs
    def pdo(self, com, mapping):
        """(COB-ID entry, transmission type, [(index, sub, bits)]) of one
        PDO from the node's own entries; None when it has none."""
        get = self.node.get_data
        try:
            cob_id = u32(get(com, 1))
            transmission = get(com, 2)[0]
            count = get(mapping, 0)[0]
            items = []
            for sub in range(1, count + 1):
                raw = u32(get(mapping, sub))
                items.append((raw >> 16, (raw >> 8) & 0xFF, raw & 0xFF))
        except canopen.SdoAbortedError:
            return None
        return cob_id, transmission, items

    def pdos(self, com_base, map_base):
        """The valid PDOs: {number: (CAN-ID, transmission, items)}."""
        found = {}
        for n in range(512):
            if com_base + n not in self.node.object_dictionary:
                continue
            pdo = self.pdo(com_base + n, map_base + n)
            if pdo and not pdo[0] & 0x80000000 and pdo[2]:
                found[n + 1] = (pdo[0] & 0x7FF, pdo[1], pdo[2])
        return found

    def drop_rpdos(self):
        for can_id, callback in self.rpdo_ids:
            self.network.unsubscribe(can_id, callback)
        self.rpdo_ids = []

    def load_pdos(self):
        """Takes the PDO configuration the master wrote."""
        self.drop_rpdos()
        for number, (can_id, _, items) in self.pdos(0x1400, 0x1600).items():
            callback = self.rpdo_callback(number, items)
            self.network.subscribe(can_id, callback)
            self.rpdo_ids.append((can_id, callback))
        self.tpdo_config = self.pdos(0x1800, 0x1A00)
        self.sync_counts = {n: 0 for n in self.tpdo_config}

    def rpdo_callback(self, number, items):
        def on_rpdo(can_id, data, timestamp):
            if self.state() != "OPERATIONAL":
                return
            values = {}
            offset = 0
            for index, sub, bits in items:
                chunk = bytes(data[offset // 8:(offset + bits) // 8])
                offset += bits
                if bits % 8 or len(chunk) * 8 != bits:
                    continue  # not byte-aligned or beyond the frame
                if index == 0 or (index < 0x1000 and index not in self.node.object_dictionary):
                    continue  # a dummy entry
                self.node.set_data(index, sub, chunk)
                values[key(index, sub)] = chunk.hex().upper()
            emit({"node": self.id, "rpdo": number, "values": values})
        return on_rpdo

    def send_tpdo(self, number):
        can_id, _, items = self.tpdo_config[number]
        data = b""
        for index, sub, bits in items:
            data += bytes(self.node.get_data(index, sub))[:bits // 8].ljust(bits // 8, b"\0")
        self.network.send_message(can_id, data)
        emit({"node": self.id, "tpdo": number, "data": data.hex().upper()})

    def on_sync(self):
        if self.state() != "OPERATIONAL":
            return
        for number, (_, transmission, _) in self.tpdo_config.items():
            if 1 <= transmission <= 240:
                self.sync_counts[number] += 1
                if self.sync_counts[number] >= transmission:
                    self.sync_counts[number] = 0
                    self.send_tpdo(number)


def main():
    cmd = json.loads(sys.argv[1])
    network = canopen.Network()
    network.connect(interface=cmd.get("interface", "socketcan"), channel=cmd["channel"])
    slaves = {}
    for spec in cmd["nodes"]:
        slaves[spec["node"]] = Slave(network, spec["node"], spec["file"])
    lock = threading.Lock()

    def on_nmt(can_id, data, timestamp):
        if len(data) < 2:
            return
        command, target = data[0], data[1]
        with lock:
            for slave in slaves.values():
                if target in (0, slave.id):
                    slave.on_nmt(command)

    def on_sync(can_id, data, timestamp):
        with lock:
            for slave in slaves.values():
                slave.on_sync()

    network.subscribe(0, on_nmt)
    network.subscribe(SYNC_ID, on_sync)
    with lock:
        for slave in slaves.values():
            slave.tpdo_config = {}
            slave.power_on()
    emit({"ready": True})

    for line in sys.stdin:
        if not line.strip():
            continue
        request = json.loads(line)
        with lock:
            slave = slaves[request["node"]]
            if request["op"] == "set":
                for name, value in request["values"].items():
                    index, sub = (int(p, 16) for p in name.split(":"))
                    slave.node.set_data(index, sub, bytes.fromhex(value))
            elif request["op"] == "tpdo":
                slave.send_tpdo(request["number"])
            elif request["op"] == "read":
                data = slave.node.get_data(request["index"], request["sub"])
                emit({"node": slave.id, "value": bytes(data).hex().upper()})
            else:
                raise ValueError("unknown op %r" % request["op"])
    for slave in slaves.values():
        slave.node.nmt.stop_heartbeat()
    network.disconnect()


if __name__ == "__main__":
    try:
        main()
    except Exception as e:  # reported to the Rust test, which fails
        traceback.print_exc()
        emit({"error": "%s: %s" % (type(e).__name__, e)})
        sys.exit(1)
