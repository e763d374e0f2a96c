#!/usr/bin/env bash
# Runs the SocketCAN tests against the real kernel CAN stack: boots Debian's
# generic kernel in qemu (software emulation) with an initramfs holding
# busybox, the CAN modules and static test binaries, creates vcan0..vcanN
# and runs the tests there (see tests/vm/README.md).
#
# Usage: tests/vm/run.sh [ARGS...]   (ARGS go to every test binary, after
#                                     --ignored)
# Exit status: 0 the tests passed, 1 a test failed inside the VM,
#              2 infrastructure failure (apt, download, build, boot,
#                timeout, missing result marker); reason on stderr.
# Environment: VM_TIMEOUT (seconds, default 480), VM_VCAN_COUNT (vcan
#              interfaces, default 10), VM_MEMORY (MiB, default 512).
set -Eeuo pipefail

infra() {
    trap - ERR
    echo "vm: INFRASTRUCTURE FAILURE: $*" >&2
    exit 2
}
trap 'infra "command failed (status $?) at tests/vm/run.sh:$LINENO: $BASH_COMMAND"' ERR

say() { echo "vm: [${SECONDS}s] $*" >&2; }

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
VM=$ROOT/target/vm
TIMEOUT=${VM_TIMEOUT:-480}
# CAN_IFACES in the VM (tests/vm/init.sh): vcan0..vcan<N-1>. Entries 0-4:
# cli/tests/live_vcan.rs, 4-7: tests/tests/vcan_python.rs, 8:
# cli/tests/monitor_vcan.rs, 9: cli/tests/sim_vcan.rs, 3:
# tests/tests/vcan_network.rs (the binaries run one after another).
VCAN_COUNT=${VM_VCAN_COUNT:-10}
MEMORY=${VM_MEMORY:-512}
TRIPLE=x86_64-unknown-linux-gnu
# The CAN modules the VM loads, in load order (vcan needs can-dev).
REQUIRED_MODULES=(can can-raw can-dev vcan)
OPTIONAL_MODULES=(can-bcm can-isotp)
# virtio-9p, in load order: the host folders python-canopen runs from.
SHARE_MODULES=(virtio_ring virtio virtio_pci_legacy_dev virtio_pci_modern_dev virtio_pci
    9pnet 9pnet_virtio netfs fscache 9p)

[[ $TIMEOUT =~ ^[0-9]+$ && $VCAN_COUNT =~ ^[0-9]+$ && $MEMORY =~ ^[0-9]+$ ]] ||
    infra "VM_TIMEOUT, VM_VCAN_COUNT and VM_MEMORY must be whole numbers"
[[ $(uname -m) == x86_64 ]] || infra "only x86_64 hosts are supported (this is $(uname -m))"
mkdir -p "$VM"
exec 9>"$VM/lock"
flock 9 || infra "cannot lock $VM/lock"

# ---------------------------------------------------------------- apt ---
# A private apt configuration: the machine's own Debian sources plus the
# <codename>-backports suite, with lists and downloads kept under target/vm.
# qemu must come from -backports: the plain suite's qemu-system-x86
# conflicts with the -backports qemu-utils some machines have.
APT=$VM/apt
CODENAME=
APT_OPTS=()
apt_setup() {
    [[ ${#APT_OPTS[@]} -gt 0 ]] && return 0
    local src=/etc/apt/sources.list.d/debian.sources
    [[ -r $src ]] || infra "$src not found: cannot derive the Debian mirror"
    CODENAME=$(. /etc/os-release && echo "${VERSION_CODENAME:-}")
    [[ -n $CODENAME ]] || infra "no VERSION_CODENAME in /etc/os-release"
    mkdir -p "$APT/lists/partial" "$APT/archives/partial" "$APT/parts.d" "$APT/deb"
    # Add <codename>-backports to every stanza that carries <codename>.
    awk -v c="$CODENAME" '
        /^Suites:/ {
            has = 0; bpo = 0
            for (i = 2; i <= NF; i++) { if ($i == c) has = 1; if ($i == c "-backports") bpo = 1 }
            if (has && !bpo) $0 = $0 " " c "-backports"
        }
        { print }' "$src" >"$APT/sources.sources"
    grep -q "$CODENAME-backports" "$APT/sources.sources" ||
        infra "no stanza for suite $CODENAME in $src"
    APT_OPTS=(
        -o "Dir::Etc::sourcelist=$APT/sources.sources"
        -o "Dir::Etc::sourceparts=$APT/parts.d"
        -o "Dir::State::lists=$APT/lists"
        -o "Dir::Cache::archives=$APT/archives"
        -o "Dir::Cache::pkgcache=" -o "Dir::Cache::srcpkgcache="
        -o "APT::Sandbox::User=root"
    )
    say "apt-get update (private lists in $APT)"
    apt-get "${APT_OPTS[@]}" -qq update >"$APT/update.log" 2>&1 ||
        infra "apt-get update failed (see $APT/update.log)"
}

# Downloads package $1 (exact name) into $APT/deb and prints the file.
apt_download() {
    (cd "$APT/deb" && apt-get "${APT_OPTS[@]}" -qq download "$1" >"$APT/download.log" 2>&1) ||
        infra "apt-get download $1 failed (see $APT/download.log)"
    local deb
    deb=$(ls -t "$APT/deb/$1"_*.deb 2>/dev/null | head -n 1)
    [[ -n $deb ]] || infra "apt-get download $1 left no .deb in $APT/deb"
    echo "$deb"
}

# ------------------------------------------------------- host tools ---
# qemu is installed (only if missing, only from -backports, and only when
# apt would neither remove nor upgrade a package); busybox-static and cpio
# are only downloaded and unpacked under target/vm.
TOOLS=$VM/tools
host_tools() {
    if ! command -v qemu-system-x86_64 >/dev/null; then
        [[ $(id -u) -eq 0 ]] || infra "qemu-system-x86_64 is missing and installing it needs root"
        apt_setup
        local sim
        sim=$(apt-get "${APT_OPTS[@]}" -s -t "$CODENAME-backports" --no-install-recommends \
            install qemu-system-x86 2>&1) || infra "apt cannot install qemu-system-x86: $(tail -n 1 <<<"$sim")"
        if grep -Eq '^(Remv|Inst [^ ]+ \[)' <<<"$sim"; then
            grep -E '^(Remv|Inst [^ ]+ \[)' <<<"$sim" >&2
            infra "installing qemu-system-x86 would remove or upgrade packages (listed above); refusing"
        fi
        say "installing qemu-system-x86 from $CODENAME-backports"
        DEBIAN_FRONTEND=noninteractive apt-get "${APT_OPTS[@]}" -y -qq -t "$CODENAME-backports" \
            --no-install-recommends install qemu-system-x86 >"$APT/install.log" 2>&1 ||
            infra "apt-get install qemu-system-x86 failed (see $APT/install.log)"
        command -v qemu-system-x86_64 >/dev/null || infra "qemu-system-x86_64 still missing after install"
    fi
    if [[ ! -x $TOOLS/busybox || ! -x $TOOLS/cpio ]]; then
        apt_setup
        rm -rf "$TOOLS.new" && mkdir -p "$TOOLS.new/x"
        local deb
        for pkg in busybox-static cpio; do
            deb=$(apt_download "$pkg")
            dpkg-deb -x "$deb" "$TOOLS.new/x" || infra "cannot unpack $deb"
        done
        cp "$TOOLS.new/x/bin/busybox" "$TOOLS.new/x/bin/cpio" "$TOOLS.new/" ||
            infra "busybox-static or cpio lacks its binary"
        rm -rf "$TOOLS.new/x" "$TOOLS" && mv "$TOOLS.new" "$TOOLS"
    fi
}

# ----------------------------------------------------------- kernel ---
# Debian's generic kernel (the -cloud- flavour has no CAN), downloaded and
# unpacked, never installed: the uncompressed vmlinux and the CAN modules.
KERNEL=$VM/kernel
kernel() {
    if [[ -f $KERNEL/done ]]; then
        local have=1 m
        for m in "${SHARE_MODULES[@]}"; do [[ -f $KERNEL/modules/$m.ko ]] || have=0; done
        [[ $have -eq 1 ]] && return 0
    fi
    apt_setup
    local pkg deb
    pkg=$(apt-cache "${APT_OPTS[@]}" depends linux-image-amd64 2>/dev/null |
        awk '$1 == "Depends:" && $2 ~ /^linux-image-[0-9].*-amd64$/ { print $2; exit }')
    [[ -n $pkg ]] || infra "cannot resolve linux-image-amd64 to a kernel package"
    say "downloading $pkg"
    deb=$(apt_download "$pkg")
    rm -rf "$KERNEL" && mkdir -p "$KERNEL/x" "$KERNEL/modules"
    dpkg-deb --fsys-tarfile "$deb" |
        tar -x -C "$KERNEL/x" --wildcards './boot/vmlinuz-*' './boot/config-*' \
            './lib/modules/*/kernel/net/can/*' './usr/lib/modules/*/kernel/net/can/*' \
            './lib/modules/*/kernel/drivers/net/can/*' './usr/lib/modules/*/kernel/drivers/net/can/*' \
            './lib/modules/*/kernel/drivers/virtio/*' './usr/lib/modules/*/kernel/drivers/virtio/*' \
            './lib/modules/*/kernel/net/9p/*' './usr/lib/modules/*/kernel/net/9p/*' \
            './lib/modules/*/kernel/fs/9p/*' './usr/lib/modules/*/kernel/fs/9p/*' \
            './lib/modules/*/kernel/fs/netfs/*' './usr/lib/modules/*/kernel/fs/netfs/*' \
            './lib/modules/*/kernel/fs/fscache/*' './usr/lib/modules/*/kernel/fs/fscache/*' \
            2>"$KERNEL/tar.log" || true
    local vmlinuz
    vmlinuz=$(ls "$KERNEL"/x/boot/vmlinuz-* 2>/dev/null | head -n 1)
    [[ -n $vmlinuz ]] || infra "no /boot/vmlinuz-* in $deb (see $KERNEL/tar.log)"
    for m in "${REQUIRED_MODULES[@]}" "${OPTIONAL_MODULES[@]}" "${SHARE_MODULES[@]}"; do
        local f
        f=$(find "$KERNEL/x" -name "$m.ko" -o -name "$m.ko.xz" | head -n 1)
        case $f in
        "") [[ " ${REQUIRED_MODULES[*]} ${SHARE_MODULES[*]} " == *" $m "* ]] &&
            infra "module $m.ko is not in $pkg" ;;
        *.xz) xz -dc "$f" >"$KERNEL/modules/$m.ko" ;;
        *) cp "$f" "$KERNEL/modules/$m.ko" ;;
        esac
    done
    # The uncompressed kernel boots seconds faster: unpack the XZ stream.
    local offset
    offset=$(grep -abo -m 1 $'\xfd7zXZ\x00' "$vmlinuz" 2>/dev/null | head -n 1 | cut -d: -f1) || true
    if [[ -n $offset ]] &&
        { tail -c +$((offset + 1)) "$vmlinuz" || true; } | xz -dc --single-stream >"$KERNEL/vmlinux" 2>/dev/null &&
        [[ $(head -c 4 "$KERNEL/vmlinux") == $'\x7fELF' ]]; then
        :
    else
        say "cannot unpack vmlinux; booting the compressed kernel"
        cp "$vmlinuz" "$KERNEL/vmlinux"
    fi
    echo "$pkg" >"$KERNEL/package"
    rm -rf "$KERNEL/x"
    touch "$KERNEL/done"
}

# ------------------------------------------------------------ tests ---
# Static test binaries without a musl target: crt-static on the explicit
# host triple (which keeps the flag off build scripts and proc macros).
BUILD=$VM/cargo
TESTBIN=$VM/tests
EXBIN=$VM/examples
CLIBIN=$VM/cli
# `cargo build` of static binaries for the VM, in the dev profile without
# debug info (half the time of release, small binaries) and without
# incremental caches (a build from scratch has no use for them, and they
# were more than half of $BUILD).
static_build() {
    (cd "$ROOT" && RUSTFLAGS="${RUSTFLAGS:-} -C target-feature=+crt-static" \
        CARGO_PROFILE_DEV_DEBUG=false CARGO_INCREMENTAL=0 \
        cargo build --target "$TRIPLE" --target-dir "$BUILD" "$@")
}
build_tests() {
    say "building static test binaries"
    local json=$VM/cargo.json
    static_build -p eds2rust-runtime --features socketcan,tokio --test socketcan_vcan \
        --message-format=json-render-diagnostics >"$json" ||
        infra "cargo build of the static test binaries failed"
    # python-canopen against our runtime over vcan (tests/tests/vcan_python.rs).
    local pyjson=$VM/cargo-python.json
    static_build -p eds2rust-tests --test vcan_python --test vcan_network \
        --message-format=json-render-diagnostics >"$pyjson" ||
        infra "cargo build of the static python-canopen test binary failed"
    # The CLI's live-bus commands (cli/tests/live_vcan.rs), `eds2rust
    # monitor` (cli/tests/monitor_vcan.rs) and `eds2rust sim`
    # (cli/tests/sim_vcan.rs), and the eds2rust binary they run, against the
    # seed-device simulators and python-canopen.
    local clijson=$VM/cargo-cli.json
    static_build -p eds2rust-cli --bin eds2rust --test live_vcan --test monitor_vcan --test sim_vcan \
        --test net_boot_vcan \
        --message-format=json-render-diagnostics >"$clijson" ||
        infra "cargo build of the static CLI and its live-bus tests failed"
    local cli
    cli=$(grep '"reason":"compiler-artifact"' "$clijson" | grep '"kind":\["bin"\]' |
        sed -n 's/.*"executable":"\([^"]*\)".*/\1/p' | head -n 1)
    [[ -n $cli ]] || infra "cargo built no eds2rust binary"
    file -b "$cli" | grep -q 'statically linked\|static-pie' || infra "$cli is not statically linked"
    rm -rf "$CLIBIN" && mkdir -p "$CLIBIN" && cp "$cli" "$CLIBIN/eds2rust"
    # The seed-device examples, each run in the VM with its simulator on its
    # own vcan interface: NMT, heartbeat, SDO, PDO (and LSS) over the kernel.
    local exjson=$VM/cargo-examples.json
    static_build -p eds2rust-sim --example zimmer_acs --example linak_techline \
        --example interroll_ec5000bi \
        --message-format=json-render-diagnostics >"$exjson" ||
        infra "cargo build of the static example binaries failed"
    rm -rf "$EXBIN" && mkdir -p "$EXBIN"
    while read -r exe; do
        [[ -n $exe ]] || continue
        file -b "$exe" | grep -q 'statically linked\|static-pie' ||
            infra "$exe is not statically linked"
        cp "$exe" "$EXBIN/"
    done < <(grep '"reason":"compiler-artifact"' "$exjson" | grep '"kind":\["example"\]' |
        sed -n 's/.*"executable":"\([^"]*\)".*/\1/p')
    rm -rf "$TESTBIN" && mkdir -p "$TESTBIN"
    local exe n=0
    while read -r exe; do
        [[ -n $exe ]] || continue
        file -b "$exe" | grep -q 'statically linked\|static-pie' ||
            infra "$exe is not statically linked"
        cp "$exe" "$TESTBIN/$(basename "$exe" | sed 's/-[0-9a-f]*$//')"
        n=$((n + 1))
    # (A binary target is marked "test":true too: only test harnesses here.)
    done < <(cat "$json" "$pyjson" "$clijson" | grep '"reason":"compiler-artifact"' | grep '"test":true' |
        grep -v '"kind":\["bin"\]' |
        sed -n 's/.*"executable":"\([^"]*\)".*/\1/p')
    [[ $n -gt 0 ]] || infra "cargo built no test executable"
}

# ----------------------------------------------------------- shares ---
# Host folders the VM mounts read-only at the same paths (virtio-9p), so
# that python-canopen runs there from the host's venv: the test scripts,
# the venv, the python it was made from and the system libraries; and the
# EDS corpus beside the checkout when it is there (cli/tests/sim_vcan.rs
# simulates one of its drives; without it the test says NOT RUN).
PYVENV=$ROOT/target/pyoracle
SHARES=()
shares() {
    local py=$PYVENV/bin/python3 prefix libdir
    if [[ ! -x $py ]] || ! prefix=$("$py" -c 'import sys; print(sys.base_prefix)' 2>/dev/null); then
        say "WARNING: no python venv at $PYVENV (the python oracle tests create it);" \
            "the python-canopen tests will fail in the VM"
        return 0
    fi
    libdir=$(dirname "$(readlink -f /lib64/ld-linux-x86-64.so.2)")
    local dir
    for dir in "$ROOT/tests/python" "$ROOT/cli/tests/python" "$ROOT/tests/networks/vm" \
        "$PYVENV" "$prefix" "$libdir"; do
        [[ -d $dir && $dir != *[[:space:]=,]* ]] || infra "cannot share $dir into the VM"
        SHARES+=("$dir")
    done
    local corpus
    corpus=$(dirname "$ROOT")/shared/eds-corpus/files
    if [[ -d $corpus && $corpus != *[[:space:]=,]* ]]; then
        SHARES+=("$corpus")
    fi
}

# -------------------------------------------------------- initramfs ---
initramfs() {
    local dir=$VM/initramfs
    rm -rf "$dir" && mkdir -p "$dir"/{bin,sbin,usr/bin,usr/sbin,proc,sys,dev,tmp,lib/modules,tests}
    cp "$TOOLS/busybox" "$dir/bin/busybox"
    cp "$ROOT/tests/vm/init.sh" "$dir/init" && chmod 755 "$dir/init"
    cp "$KERNEL"/modules/*.ko "$dir/lib/modules/"
    # The dynamic loader and libraries of the shared python come from the
    # host's library folder, mounted at its own path.
    local libdir
    libdir=$(dirname "$(readlink -f /lib64/ld-linux-x86-64.so.2)")
    mkdir -p "$dir/lib64"
    [[ $libdir == /lib/* ]] || ln -s "$libdir" "$dir/lib/$(basename "$libdir")"
    ln -s "$libdir/ld-linux-x86-64.so.2" "$dir/lib64/ld-linux-x86-64.so.2"
    cp "$TESTBIN"/* "$dir/tests/"
    mkdir -p "$dir/examples" && cp "$EXBIN"/* "$dir/examples/"
    mkdir -p "$dir/cli" && cp "$CLIBIN"/* "$dir/cli/"
    {
        echo "VCAN_COUNT=$VCAN_COUNT"
        echo "REQUIRED_MODULES='${REQUIRED_MODULES[*]}'"
        echo "OPTIONAL_MODULES='${OPTIONAL_MODULES[*]}'"
        echo "SHARE_MODULES='${SHARE_MODULES[*]}'"
        local i=0 list=
        for d in "${SHARES[@]}"; do list="$list${list:+ }share$i=$d"; i=$((i + 1)); done
        echo "SHARES='$list'"
    } >"$dir/vmtest.conf"
    # Test arguments, one a line (ash has no arrays).
    { echo --ignored; for a in "$@"; do echo "$a"; done; } >"$dir/vmtest.args"
    (cd "$dir" && find . | LC_ALL=C sort | "$TOOLS/cpio" -o -H newc --quiet >"$VM/initramfs.cpio") ||
        infra "cannot pack the initramfs"
}

# ------------------------------------------------------------- boot ---
# Exit status of qemu with isa-debug-exit: (code << 1) | 1. The verdict is
# the marker the VM writes to its second serial port (result.txt).
boot() {
    local result=$VM/result.txt console=$VM/console.log
    rm -f "$result" "$console" "$VM/qemu.status"
    say "booting $(cat "$KERNEL/package") (timeout ${TIMEOUT}s)"
    local virtfs=() i=0 d
    for d in "${SHARES[@]}"; do
        virtfs+=(-virtfs "local,path=$d,mount_tag=share$i,security_model=none,readonly=on")
        i=$((i + 1))
    done
    {
        local s=0
        timeout -k 5 "$TIMEOUT" qemu-system-x86_64 -accel tcg -cpu max -m "$MEMORY" -smp 2 \
            -nodefaults -no-user-config -display none -no-reboot -net none \
            -kernel "$KERNEL/vmlinux" -initrd "$VM/initramfs.cpio" \
            -append "console=ttyS0 panic=-1 quiet loglevel=3" \
            -serial stdio -chardev "file,id=res,path=$result" -serial chardev:res \
            -device isa-debug-exit,iobase=0xf4,iosize=0x04 "${virtfs[@]}" </dev/null 2>"$VM/qemu.err" || s=$?
        echo "$s" >"$VM/qemu.status"
    } | tee "$console"
    local status
    status=$(cat "$VM/qemu.status")
    if [[ $status -eq 124 || $status -eq 137 ]]; then
        infra "the VM did not finish within ${TIMEOUT}s (VM_TIMEOUT); console in $console"
    fi
    local marker
    marker=$(grep -a -m 1 -o 'VMTEST-[A-Z]*.*' "$result" 2>/dev/null | tr -d '\r') || true
    case $marker in
    "VMTEST-RESULT rc=0")
        say "PASS: all tests passed in the VM"
        exit 0
        ;;
    "VMTEST-RESULT rc="*)
        echo "vm: TEST FAILURE: a test failed inside the VM ($marker); console in $console" >&2
        exit 1
        ;;
    "VMTEST-SETUP-FAILED"*)
        infra "VM setup failed: ${marker#VMTEST-SETUP-FAILED }"
        ;;
    *)
        local why="qemu exited with status $status"
        [[ -s $VM/qemu.err ]] && why="$why: $(head -n 1 "$VM/qemu.err")"
        infra "no result marker from the VM (boot failure?); $why; console in $console"
        ;;
    esac
}

say "qemu-img before: $(qemu-img --version 2>/dev/null | head -n 1 || echo none)"
host_tools
kernel
build_tests
shares
initramfs "$@"
say "qemu-img after: $(qemu-img --version 2>/dev/null | head -n 1 || echo none)"
boot
