"""Writes a bus file as ros2_canopen hands it to lely's dcfgen.

dcfgen does not know ros2_canopen's `defaults:`/`nodes:`: before calling it,
ros2_canopen writes a new file of `options:`, `master:` and one slave section
per entry of `nodes:`, with the keys of `defaults:` put over the node's own
(the defaults win); a flat slave section beside `nodes:` is not carried
over. The file is dumped with its keys sorted, so the slaves (which number
the master's PDOs) come in name order. A file without `nodes:` is dcfgen's
own format and is written as read.

usage: expand_bus.py BUS_YML OUT_YML
       expand_bus.py --check BUS_YML EXPANDED_YML  (exit 1 when they differ)
"""

import sys

import yaml


def expand(cfg):
    if "nodes" not in cfg:
        return cfg, False
    defaults = cfg.get("defaults") or {}
    expanded = {"options": cfg.get("options") or {}, "master": cfg.get("master") or {}}
    for name, node in (cfg["nodes"] or {}).items():
        slave = dict(node or {})
        slave.update(defaults)
        expanded[name] = slave
    return expanded, True


def main():
    if sys.argv[1] == "--check":
        with open(sys.argv[2], "r") as f:
            cfg, _ = expand(yaml.safe_load(f))
        with open(sys.argv[3], "r") as f:
            expected = yaml.safe_load(f)
        if cfg != expected:
            sys.exit("the expansion of {} differs from {}".format(sys.argv[2], sys.argv[3]))
        return
    source, target = sys.argv[1], sys.argv[2]
    with open(source, "r") as f:
        cfg = yaml.safe_load(f)
    cfg, expanded = expand(cfg)
    with open(target, "w") as f:
        if expanded:
            yaml.safe_dump(cfg, f, sort_keys=True)
        else:
            with open(source, "r") as original:
                f.write(original.read())


if __name__ == "__main__":
    main()
