#!/bin/busybox sh
# /init of the test VM (busybox ash): loads the CAN modules, creates
# vcan0..vcan<N-1>, runs every binary in /tests, then reports on the second
# serial port (the host's result.txt) and through the isa-debug-exit port:
#   VMTEST-RESULT rc=<n>          the tests ran; 0 = all passed
#   VMTEST-SETUP-FAILED <reason>  the VM could not set up (infrastructure)
/bin/busybox mkdir -p /bin /sbin /usr/bin /usr/sbin
/bin/busybox --install -s
export PATH=/bin:/sbin:/usr/bin:/usr/sbin
mount -t proc proc /proc
mount -t sysfs sysfs /sys
mount -t devtmpfs devtmpfs /dev
mount -t tmpfs tmpfs /tmp

# Writes the marker, exits qemu with status (rc << 1) | 1, powers off.
finish() {
    echo "$1"
    echo "$1" >/dev/ttyS1
    printf "\\$(printf %03o "$2")" | dd of=/dev/port bs=1 seek=244 count=1 conv=notrunc 2>/dev/null
    poweroff -f
    sleep 10
}

setup_failed() {
    finish "VMTEST-SETUP-FAILED $*" 2
}

[ -r /vmtest.conf ] || setup_failed "no /vmtest.conf in the initramfs"
. /vmtest.conf

for m in $REQUIRED_MODULES; do
    out=$(insmod "/lib/modules/$m.ko" 2>&1) || setup_failed "insmod $m: $out"
done
for m in $OPTIONAL_MODULES; do
    [ -f "/lib/modules/$m.ko" ] && insmod "/lib/modules/$m.ko" 2>/dev/null
done

# Host folders shared read-only (virtio-9p) at their own paths: the python
# venv and what it needs, for the python-canopen tests.
if [ -n "$SHARES" ]; then
    for m in $SHARE_MODULES; do
        out=$(insmod "/lib/modules/$m.ko" 2>&1) || setup_failed "insmod $m: $out"
    done
    for share in $SHARES; do
        tag=${share%%=*}
        dir=${share#*=}
        mkdir -p "$dir"
        out=$(mount -t 9p -o trans=virtio,version=9p2000.L,ro,cache=loose,msize=262144 \
            "$tag" "$dir" 2>&1) || setup_failed "mounting $tag at $dir: $out"
    done
    echo "vm: mounted $SHARES"
fi
export PYTHONDONTWRITEBYTECODE=1

ip link set lo up
ifaces=
i=0
while [ "$i" -lt "$VCAN_COUNT" ]; do
    out=$({ ip link add dev "vcan$i" type vcan &&
        ip link set "vcan$i" mtu 72 &&
        ip link set up "vcan$i"; } 2>&1) || setup_failed "creating vcan$i: $out"
    ifaces="$ifaces${ifaces:+ }vcan$i"
    i=$((i + 1))
done
if [ -n "$ifaces" ]; then
    export CAN_IFACE=vcan0 CAN_IFACES="$ifaces"
    echo "vm: created $ifaces"
else
    echo "vm: no vcan interfaces (VM_VCAN_COUNT=0)"
fi

set --
while IFS= read -r arg; do
    set -- "$@" "$arg"
done </vmtest.args

export RUST_BACKTRACE=1
# The eds2rust binary the CLI's live-bus tests run (cli/tests/live_vcan.rs).
export EDS2RUST_CLI=/cli/eds2rust
rc=0
ran=0
for t in /tests/*; do
    [ -x "$t" ] || continue
    ran=$((ran + 1))
    echo "vm: running ${t#/tests/} $*"
    "$t" "$@"
    status=$?
    echo "vm: ${t#/tests/} exited with status $status"
    [ "$status" -eq 0 ] || rc=1
done
[ "$ran" -gt 0 ] || setup_failed "no test binary in /tests"

# The seed-device examples: master and simulator on one vcan interface
# each (their own sockets), mechanics 20 times faster than real time.
n=0
for e in /examples/*; do
    [ -x "$e" ] || continue
    iface=vcan$n
    n=$((n + 1))
    echo "vm: running example ${e#/examples/} --iface $iface --simulate --time-scale 20"
    "$e" --iface "$iface" --simulate --time-scale 20
    status=$?
    echo "vm: example ${e#/examples/} exited with status $status"
    [ "$status" -eq 0 ] || rc=1
done
finish "VMTEST-RESULT rc=$rc" "$rc"
