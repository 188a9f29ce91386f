#!/bin/sh
# SPDX-License-Identifier: MIT
# Runs a command in a private network namespace whose only interface is the loopback, with
# 127.0.0.2 .. 127.0.0.5 added to it, so that GigE Vision tests (Aravis's fake cameras,
# discovery broadcasts) never send a packet beyond this machine.
#
# usage: scripts/netns-test.sh COMMAND [ARGS...]
# CTest wraps every Aravis test executable with it (tests/plugins_gige/CMakeLists.txt).
set -eu

if [ "${1:-}" != "--inside-namespace" ]; then
    if [ "$(id -u)" = 0 ]; then
        exec unshare --net -- "$0" --inside-namespace "$@"
    fi
    # Not root: a user namespace grants the rights to configure the new network namespace.
    exec unshare --map-root-user --net -- "$0" --inside-namespace "$@"
fi
shift

command -v ip >/dev/null 2>&1 || { echo "netns-test.sh: 'ip' not found (install iproute2)" >&2; exit 2; }
ip link set lo up
for n in 2 3 4 5; do
    ip addr add "127.0.0.$n/8" dev lo
done
# Only lo may be visible here; refuse to run the command otherwise.
others=$(ip -o link show | awk -F': ' '$2 != "lo" {print $2}')
[ -z "$others" ] || { echo "netns-test.sh: interfaces visible besides lo: $others; not isolated" >&2; exit 2; }
exec "$@"
