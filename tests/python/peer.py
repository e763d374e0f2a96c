"""A python-canopen peer for the interop tests, driven over stdin/stdout.

python-canopen runs on a python-can virtual bus; a second virtual bus on the
same channel (the bridge) connects that bus to the Rust side. One line per
message, both ways:

    F <frame>    a CAN frame in candump compact form (123#11223344, 123#R,
                 123#R1, 12345678#..., uppercase hex). From stdin: sent on
                 the bridge, so python-canopen receives it. To stdout: every
                 frame python-canopen sends.
    C <json>     (stdin) a command with an "id" and an "op"; answered by
    R <json>     (stdout) with the same "id" once the command finished.
    Q            (stdin) quit; so does the end of stdin.

A reply holds "ok": true and the results, or {"abort": code} when an SDO
transfer was aborted (SdoAbortedError.code), or {"error": "..."} for any
other exception (timeouts included; the traceback goes to stderr). Values
are hex strings. Every command runs in its own thread, so frames keep
flowing while python-canopen blocks.

Operations ("op"; see each op_* method): local_node, set, get, local_state,
clear_abort (LocalNode: SDO server, NMT slave, heartbeat and EMCY producer);
upload, download, nmt_command, remote_state, wait_heartbeat, emcy_log
(RemoteNode: SDO client, NMT master, heartbeat and EMCY consumer);
local_nmt, heartbeat_start, heartbeat_stop, emcy; barrier and send (marker
frames on id 0x7FF, to order frames against commands); ping, dump_threads,
exit (diagnostics). For recorded sessions: sdo_log_start, sdo_transfer,
sdo_log (a RemoteNode's transfers, logged with their protocol), sync (SYNC
producer), pdo_listen, pdo_log (every TPDO reception, decoded). The network holds one node per id: a LocalNode and a
RemoteNode cannot share one.
"""

import binascii
import faulthandler
import json
import os
import sys
import threading
import traceback

import can
import canopen
from canopen.objectdictionary import ODRecord, ODVariable, ObjectDictionary
from canopen.objectdictionary import datatypes
from canopen.sdo import SdoAbortedError

OUT_LOCK = threading.Lock()
# The identifier of barrier markers; CANopen does not use it.
MARKER_ID = 0x7FF
# The number of heartbeat states kept per remote node.
HEARD_KEPT = 256


def emit(line):
    """Writes one line to stdout at once and flushes it."""
    with OUT_LOCK:
        sys.stdout.write(line + "\n")
        sys.stdout.flush()


def format_frame(msg):
    """candump compact form of a python-can message."""
    if msg.is_extended_id:
        text = "%08X#" % msg.arbitration_id
    else:
        text = "%03X#" % msg.arbitration_id
    if msg.is_remote_frame:
        text += "R"
        if msg.dlc:
            text += "%d" % msg.dlc
        return text
    return text + bytes(msg.data).hex().upper()


def parse_frame(text):
    """A python-can message from candump compact form."""
    ident, sep, rest = text.strip().partition("#")
    if not sep or not ident:
        raise ValueError("not a candump frame: %r" % text)
    extended = len(ident) > 3
    arbitration_id = int(ident, 16)
    if rest.upper().startswith("R"):
        dlc = int(rest[1:]) if len(rest) > 1 else 0
        return can.Message(arbitration_id=arbitration_id, is_extended_id=extended,
                           is_remote_frame=True, dlc=dlc)
    data = binascii.unhexlify(rest)
    return can.Message(arbitration_id=arbitration_id, is_extended_id=extended,
                       data=data)


def unhex(text):
    return binascii.unhexlify(text or "")


def json_value(value):
    """A decoded value as JSON takes it (bytes as hex)."""
    if isinstance(value, (bytes, bytearray)):
        return bytes(value).hex().upper()
    return value


class Peer:
    """The python-canopen side: one network, its nodes, and the bridge."""

    def __init__(self):
        channel = "eds2rust-peer-%d" % os.getpid()
        self.network = canopen.Network()
        self.network.connect(interface="virtual", channel=channel)
        self.bridge = can.Bus(interface="virtual", channel=channel)
        self.local = {}
        self.remote = {}
        # Raw state bytes of every heartbeat/boot-up per remote node.
        self.heard = {}
        self.lock = threading.Lock()
        self.running = True
        # Barrier markers (id 0x7FF) python-canopen has received.
        self.markers = set()
        self.marker_seen = threading.Condition()
        self.network.subscribe(MARKER_ID, self.on_marker)

    def on_marker(self, can_id, data, timestamp):
        with self.marker_seen:
            self.markers.add(bytes(data).hex().upper())
            self.marker_seen.notify_all()

    # Nodes ---------------------------------------------------------------

    def local_node(self, node):
        try:
            return self.local[node]
        except KeyError:
            raise ValueError("no LocalNode %d (create it with op local_node)" % node)

    def remote_node(self, node):
        with self.lock:
            found = self.remote.get(node)
            if found is None and node in self.local:
                # One network holds one node per id: adding a RemoteNode
                # would silently detach the LocalNode.
                raise ValueError("node %d is a LocalNode of this peer" % node)
            if found is None:
                found = self._add_remote(node, ObjectDictionary())
            return found

    def _add_remote(self, node, od):
        """Adds a RemoteNode with dictionary `od` (an ObjectDictionary or an
        EDS path) that records its heartbeats; the caller holds the lock."""
        remote = canopen.RemoteNode(node, od)
        heard = self.heard.setdefault(node, [])

        def on_heartbeat(state, heard=heard):
            if len(heard) < HEARD_KEPT:
                heard.append(state)
        remote.nmt.add_heartbeat_callback(on_heartbeat)
        self.network.add_node(remote)
        self.remote[node] = remote
        return remote

    # Commands ------------------------------------------------------------

    def op_ping(self, cmd):
        return {}

    def op_barrier(self, cmd):
        """Waits until python-canopen received the marker frame with data
        "token" (sent just before this command), so every frame sent before
        it has been handled."""
        token = cmd["token"].upper()
        with self.marker_seen:
            if not self.marker_seen.wait_for(lambda: token in self.markers,
                                             cmd.get("timeout", 5.0)):
                raise TimeoutError("marker %s did not arrive" % token)
            self.markers.discard(token)
        return {}

    def op_dump_threads(self, cmd):
        """Writes the stack of every Python thread to stderr (diagnostics)."""
        faulthandler.dump_traceback(file=sys.stderr, all_threads=True)
        sys.stderr.flush()
        return {}

    def op_exit(self, cmd):
        """Ends the process at once with a message on stderr (to test how
        the Rust side reports a dead peer)."""
        print(cmd.get("message", "exiting"), file=sys.stderr, flush=True)
        os._exit(cmd.get("code", 1))

    def op_send(self, cmd):
        """Sends a raw frame from python-canopen's network."""
        msg = parse_frame(cmd["frame"])
        with self.network.send_lock:
            self.network.bus.send(msg)
        return {}

    def op_local_node(self, cmd):
        """A LocalNode (SDO server, NMT slave, EMCY and heartbeat producer)
        with an object dictionary of the given entries:
        {"index", "sub", "type" (datatypes name), "access", "value" (hex)}."""
        node = cmd["node"]
        od = ObjectDictionary()
        entries = list(cmd.get("objects", []))
        if not any(e["index"] == 0x1017 for e in entries):
            # NmtSlave reads the heartbeat producer time on boot-up.
            entries.append({"index": 0x1017, "sub": 0, "type": "UNSIGNED16",
                            "access": "rw", "value": "0000"})
        by_index = {}
        for entry in entries:
            by_index.setdefault(entry["index"], []).append(entry)
        initial = []
        for index, members in sorted(by_index.items()):
            if len(members) == 1 and members[0].get("sub", 0) == 0:
                var = self._variable(members[0])
                od.add_object(var)
            else:
                record = ODRecord("record_%04X" % index, index)
                if not any(m.get("sub", 0) == 0 for m in members):
                    count = max(m["sub"] for m in members)
                    members.append({"index": index, "sub": 0, "type": "UNSIGNED8",
                                    "access": "ro", "value": "%02X" % count})
                for member in members:
                    record.add_member(self._variable(member))
                od.add_object(record)
            for member in members:
                if member.get("value") is not None:
                    initial.append(member)
        local = canopen.LocalNode(node, od)
        for entry in initial:
            local.data_store.setdefault(entry["index"], {})[entry.get("sub", 0)] = \
                unhex(entry["value"])
        with self.lock:
            if node in self.remote:
                raise ValueError("node %d is a RemoteNode of this peer" % node)
            old = self.local.pop(node, None)
            if old is not None:
                old.nmt.stop_heartbeat()
                self.network.pop(node, None)
            self.network.add_node(local)
            self.local[node] = local
        return {}

    @staticmethod
    def _variable(entry):
        var = ODVariable("obj_%04X_%02X" % (entry["index"], entry.get("sub", 0)),
                         entry["index"], entry.get("sub", 0))
        var.data_type = getattr(datatypes, entry.get("type", "DOMAIN"))
        var.access_type = entry.get("access", "rw")
        return var

    def op_set(self, cmd):
        """Sets a LocalNode value as the application would (no access check)."""
        self.local_node(cmd["node"]).set_data(cmd["index"], cmd.get("sub", 0),
                                              unhex(cmd["value"]))
        return {}

    def op_get(self, cmd):
        """The value a LocalNode holds."""
        data = self.local_node(cmd["node"]).get_data(cmd["index"], cmd.get("sub", 0))
        return {"value": bytes(data).hex().upper()}

    def op_local_state(self, cmd):
        """NMT state and the last abort code a LocalNode's SDO server received."""
        local = self.local_node(cmd["node"])
        return {"state": local.nmt.state, "code": local.nmt._state,
                "last_abort": local.sdo.last_received_error}

    def op_clear_abort(self, cmd):
        self.local_node(cmd["node"]).sdo.last_received_error = 0
        return {}

    def op_upload(self, cmd):
        """SDO upload by a RemoteNode client; "block" uses block upload."""
        sdo = self.remote_node(cmd["node"]).sdo
        sdo.RESPONSE_TIMEOUT = cmd.get("timeout", 1.0)
        index, sub = cmd["index"], cmd.get("sub", 0)
        if cmd.get("block"):
            with sdo.open(index, sub, "rb", block_transfer=True,
                          request_crc_support=cmd.get("crc", True)) as fp:
                data = fp.read()
        else:
            data = sdo.upload(index, sub)
        return {"value": bytes(data).hex().upper()}

    def op_download(self, cmd):
        """SDO download by a RemoteNode client; "block" uses block download,
        "segmented" forces a segmented one."""
        sdo = self.remote_node(cmd["node"]).sdo
        sdo.RESPONSE_TIMEOUT = cmd.get("timeout", 1.0)
        index, sub = cmd["index"], cmd.get("sub", 0)
        data = unhex(cmd["value"])
        if cmd.get("block"):
            with sdo.open(index, sub, "wb", size=len(data), block_transfer=True,
                          request_crc_support=cmd.get("crc", True)) as fp:
                fp.write(data)
        else:
            sdo.download(index, sub, data, force_segment=cmd.get("segmented", False))
        return {}

    def op_nmt_command(self, cmd):
        """Sends an NMT command (numeric command specifier) to one node
        (a RemoteNode's NmtMaster) or, with node 0, to all."""
        node = cmd.get("node", 0)
        master = self.network.nmt if node == 0 else self.remote_node(node).nmt
        master.send_command(cmd["command"])
        return {}

    def op_local_nmt(self, cmd):
        """Sets a LocalNode's NMT state by name (INITIALISING sends boot-up)."""
        self.local_node(cmd["node"]).nmt.state = cmd["state"]
        return {}

    def op_heartbeat_start(self, cmd):
        self.local_node(cmd["node"]).nmt.start_heartbeat(cmd["period_ms"])
        return {}

    def op_heartbeat_stop(self, cmd):
        self.local_node(cmd["node"]).nmt.stop_heartbeat()
        return {}

    def op_remote_state(self, cmd):
        """The NMT state python-canopen tracks for a remote node, and the
        state bytes of every heartbeat and boot-up it received ("heard")."""
        node = self.remote_node(cmd["node"])
        return {"state": node.nmt.state, "code": node.nmt._state,
                "heard": list(self.heard.get(cmd["node"], []))}

    def op_wait_heartbeat(self, cmd):
        """Waits for the next heartbeat of a remote node; its state."""
        nmt = self.remote_node(cmd["node"]).nmt
        state = nmt.wait_for_heartbeat(cmd.get("timeout", 2.0))
        return {"state": state, "code": nmt._state}

    def op_emcy(self, cmd):
        """Sends an EMCY from a LocalNode."""
        self.local_node(cmd["node"]).emcy.send(cmd["code"], cmd.get("register", 0),
                                               unhex(cmd.get("data", "")))
        return {}

    def op_emcy_log(self, cmd):
        """The EMCY messages python-canopen received from a remote node."""
        log = self.remote_node(cmd["node"]).emcy.log
        return {"log": [{"code": e.code, "register": e.register,
                         "data": bytes(e.data).hex().upper()} for e in log]}

    # Plumbing ------------------------------------------------------------

    # PDOs of a RemoteNode with an object dictionary -----------------------

    def op_remote_node_eds(self, cmd):
        """Replaces RemoteNode `node` by one whose object dictionary is the
        EDS file `eds` (needed to name and decode PDO variables)."""
        node = cmd["node"]
        with self.lock:
            old = self.remote.pop(node, None)
            if old is not None:
                self.network.nodes.pop(node, None)
            self._add_remote(node, cmd["eds"])
        return {}

    def op_tpdo_read(self, cmd):
        """Reads every TPDO's configuration over SDO (PdoMap.read with
        from_od=False), which also subscribes to the PDOs."""
        remote = self.remote_node(cmd["node"])
        remote.sdo.RESPONSE_TIMEOUT = cmd.get("timeout", 1.0)
        remote.tpdo.read(from_od=False)
        maps = []
        for number, pdo_map in sorted(remote.tpdo.map.items()):
            maps.append({
                "number": number,
                "cob_id": pdo_map.cob_id,
                "enabled": pdo_map.enabled,
                "trans_type": pdo_map.trans_type,
                "event_timer": pdo_map.event_timer,
                "inhibit_time": pdo_map.inhibit_time,
                "map": [[v.index, v.subindex, v.length] for v in pdo_map.map],
            })
        return {"maps": maps}

    def op_tpdo_arm(self, cmd):
        """Forgets the receptions of TPDO `number` so far: a tpdo_wait started
        after this command's reply returns on the first reception after it
        (python-canopen's wait_for_reception would miss a TPDO that comes
        before its thread starts waiting)."""
        pdo_map = self.remote_node(cmd["node"]).tpdo.map[cmd["number"]]
        with pdo_map.receive_condition:
            pdo_map.is_received = False
        return {}

    def op_tpdo_wait(self, cmd):
        """Waits for a reception of TPDO `number` since its last tpdo_arm (any
        reception so far, if it was never armed) and returns the data of the
        latest and every variable's decoded raw value."""
        pdo_map = self.remote_node(cmd["node"]).tpdo.map[cmd["number"]]
        with pdo_map.receive_condition:
            pdo_map.receive_condition.wait_for(
                lambda: pdo_map.is_received, timeout=cmd.get("timeout", 2.0))
        if not pdo_map.is_received:
            raise ValueError("TPDO %d of node %d was not received" %
                             (cmd["number"], cmd["node"]))
        with pdo_map.receive_condition:
            data = bytes(pdo_map.data)
            values = [[v.index, v.subindex, v.raw] for v in pdo_map.map]
        return {"data": data.hex().upper(), "values": values}

    # Logged SDO transfers, SYNC and PDO receptions, for recorded sessions -

    def op_sdo_log_start(self, cmd):
        """From now on, logs every SDO transfer of RemoteNode `node`'s client:
        its upload() and download() (which python-canopen's SdoVariable, and
        so PdoMap.read, use) and the transfers of op sdo_transfer. Each is
        logged as it ends, with its protocol, the bytes it moved and its
        abort code, for op sdo_log."""
        sdo = self.remote_node(cmd["node"]).sdo
        if getattr(sdo, "eds2rust_log", None) is None:
            sdo.eds2rust_log = []

            def upload(index, subindex, sdo=sdo):
                return self._transfer(sdo, index, subindex, upload=True)

            def download(index, subindex, data, force_segment=False, sdo=sdo):
                self._transfer(sdo, index, subindex, upload=False, data=data,
                               force_segment=force_segment)
            # Instance attributes: they shadow the methods for every caller.
            sdo.upload = upload
            sdo.download = download
        return {}

    def _transfer(self, sdo, index, sub, upload, data=b"", block=False,
                  force_segment=False, crc=True):
        """One SDO transfer as SdoClient.upload/download or sdo.open with
        block_transfer do it, logged when op sdo_log_start was run. Returns
        the value (uploads: cut to a fixed-size variable's length, as
        SdoClient.upload does)."""
        entry = {"index": index, "sub": sub, "upload": upload, "block": block,
                 "segmented": False, "value": ""}
        value = data
        try:
            if upload and block:
                with sdo.open(index, sub, "rb", block_transfer=True,
                              request_crc_support=crc) as fp:
                    value = fp.read()
            elif upload:
                with sdo.open(index, sub, buffering=0) as fp:
                    entry["segmented"] = fp.exp_data is None
                    response_size = fp.size
                    value = fp.read()
            elif block:
                with sdo.open(index, sub, "wb", size=len(data), block_transfer=True,
                              request_crc_support=crc) as fp:
                    fp.write(data)
            else:
                # python-canopen's rule (WritableStream): expedited for 1 to 4
                # bytes unless forced.
                entry["segmented"] = not 1 <= len(data) <= 4 or force_segment
                with sdo.open(index, sub, "wb", buffering=7, size=len(data),
                              force_segment=force_segment) as fp:
                    fp.write(data)
            entry["value"] = bytes(value).hex().upper()
        except SdoAbortedError as exc:
            entry["abort"] = exc.code
            raise
        except Exception as exc:
            entry["error"] = "%s: %s" % (type(exc).__name__, exc)
            raise
        finally:
            log = getattr(sdo, "eds2rust_log", None)
            if log is not None:
                log.append(entry)
        if upload and not block:
            var = sdo.od.get_variable(index, sub)
            if var is not None and var.fixed_size:
                size = len(var) // 8
                if response_size is None or size < response_size:
                    value = value[0:size]
        return value

    def op_sdo_transfer(self, cmd):
        """An SDO transfer by RemoteNode `node`'s client: "upload" true or
        false, "block" for a block transfer, "segmented" to force a
        segmented download, "crc" (block: request CRC support, default
        true), "value" (downloads, hex). Uploads reply the value."""
        sdo = self.remote_node(cmd["node"]).sdo
        sdo.RESPONSE_TIMEOUT = cmd.get("timeout", 1.0)
        value = self._transfer(sdo, cmd["index"], cmd.get("sub", 0),
                               upload=cmd["upload"], data=unhex(cmd.get("value")),
                               block=cmd.get("block", False),
                               force_segment=cmd.get("segmented", False),
                               crc=cmd.get("crc", True))
        return {"value": bytes(value).hex().upper()}

    def op_sdo_log(self, cmd):
        """The transfers logged since op sdo_log_start (and empties the log):
        {"index", "sub", "upload", "block", "segmented" (a standard transfer
        that was not expedited), "value" (hex), "abort" (when aborted)}."""
        sdo = self.remote_node(cmd["node"]).sdo
        log = getattr(sdo, "eds2rust_log", None)
        if log is None:
            raise ValueError("no SDO log for node %d (op sdo_log_start)" % cmd["node"])
        entries = list(log)
        del log[:len(entries)]
        return {"log": entries}

    def op_sync(self, cmd):
        """Sends `count` SYNC messages (default 1) with python-canopen's SYNC
        producer (network.sync.transmit)."""
        for _ in range(cmd.get("count", 1)):
            self.network.sync.transmit()
        return {}

    def op_pdo_listen(self, cmd):
        """Logs every reception of RemoteNode `node`'s TPDOs (the maps read
        with op tpdo_read): the map number, COB-ID, data and each mapped
        variable's name, index, sub-index and raw value, decoded by
        python-canopen when the frame came (a PdoMap callback)."""
        remote = self.remote_node(cmd["node"])
        if getattr(remote, "eds2rust_pdo_log", None) is None:
            remote.eds2rust_pdo_log = []
            remote.eds2rust_pdo_seen = threading.Condition()

            def received(pdo_map, number, remote=remote):
                fields = [[v.name, v.index, v.subindex, json_value(v.raw)]
                          for v in pdo_map.map]
                with remote.eds2rust_pdo_seen:
                    remote.eds2rust_pdo_log.append({
                        "number": number,
                        "cob_id": pdo_map.cob_id,
                        "data": bytes(pdo_map.data).hex().upper(),
                        "fields": fields,
                    })
                    remote.eds2rust_pdo_seen.notify_all()
            for number, pdo_map in remote.tpdo.map.items():
                pdo_map.add_callback(
                    lambda m, number=number: received(m, number))
        return {}

    def op_pdo_log(self, cmd):
        """The receptions logged since op pdo_listen, after waiting up to
        "timeout" seconds until there are at least "count"."""
        remote = self.remote_node(cmd["node"])
        seen = getattr(remote, "eds2rust_pdo_seen", None)
        if seen is None:
            raise ValueError("no PDO log for node %d (op pdo_listen)" % cmd["node"])
        count = cmd.get("count", 0)
        with seen:
            if not seen.wait_for(lambda: len(remote.eds2rust_pdo_log) >= count,
                                 cmd.get("timeout", 2.0)):
                raise TimeoutError("%d of %d PDOs received" %
                                   (len(remote.eds2rust_pdo_log), count))
            return {"log": list(remote.eds2rust_pdo_log)}

    def run_command(self, cmd):
        reply = {"id": cmd.get("id")}
        try:
            handler = getattr(self, "op_" + str(cmd.get("op")), None)
            if handler is None:
                raise ValueError("unknown op %r" % cmd.get("op"))
            result = handler(cmd)
            reply.update(result)
            reply["ok"] = True
        except SdoAbortedError as exc:
            reply["abort"] = exc.code
        except Exception as exc:  # reported to the Rust side, never fatal
            traceback.print_exc(file=sys.stderr)
            sys.stderr.flush()
            reply["error"] = "%s: %s" % (type(exc).__name__, exc)
        emit("R " + json.dumps(reply))

    def forward_frames(self):
        """Bridge to stdout: every frame python-canopen sends."""
        while self.running:
            msg = self.bridge.recv(0.2)
            if msg is not None and not msg.is_error_frame:
                emit("F " + format_frame(msg))

    def serve(self):
        threading.Thread(target=self.forward_frames, daemon=True).start()
        for line in sys.stdin:
            line = line.rstrip("\r\n")
            if not line:
                continue
            kind, _, rest = line.partition(" ")
            if kind == "F":
                try:
                    self.bridge.send(parse_frame(rest))
                except Exception:
                    traceback.print_exc(file=sys.stderr)
                    sys.stderr.flush()
            elif kind == "C":
                try:
                    cmd = json.loads(rest)
                except ValueError as exc:
                    emit("R " + json.dumps({"id": None, "error": "bad JSON: %s" % exc}))
                    continue
                threading.Thread(target=self.run_command, args=(cmd,),
                                 daemon=True).start()
            elif kind == "Q":
                break
            else:
                print("peer.py: unknown line %r" % line, file=sys.stderr, flush=True)
        self.running = False
        for local in list(self.local.values()):
            local.nmt.stop_heartbeat()


def main():
    peer = Peer()
    emit("R " + json.dumps({"id": 0, "ok": True, "ready": True}))
    peer.serve()
    # Daemon threads and the notifier die with the process.
    os._exit(0)


if __name__ == "__main__":
    main()
