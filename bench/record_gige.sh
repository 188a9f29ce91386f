#!/bin/sh
# SPDX-License-Identifier: MIT
# Timed run: `binocle record` from two external fake GigE Vision cameras
# (arv-fake-gv-camera-0.8 on 127.0.0.2 and 127.0.0.3, separate processes), 640x480 Mono8,
# free running, in a private network namespace (scripts/netns-test.sh: nothing leaves lo).
# Two runs, same cameras, one after the other:
#   before: the transport and writer of before issue 10 (kernel-default 208 KiB socket
#           buffer, 8 stream buffers, one writer thread that the grab waits for)
#   now:    the shipped rig's defaults (configs/rigs/gige-two-cameras.yaml)
#   mcap:   the same as now, --format mcap (a rosbag2 bag, zstd chunks; FORMAT mcap or both)
# Each run stops after PAIRS pairs or its time (30 s before, 150 s now and mcap; one SIGINT:
# a clean stop) and prints, per run, pairs written per second and per image the cameras
# sent, every loss by place, the size of what it wrote, and the ratios to `before`.
#
# usage: bench/record_gige.sh [PAIRS [RATE_HZ [FORMAT]]]   (default 1000 pairs at 100 Hz,
#        FORMAT folder: before and now; mcap: now as a bag only; both: before, now and mcap)
#        BINOCLE_BUILD_DIR=build (default)
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
if [ "${1:-}" != "--inside" ]; then
    exec "$here/scripts/netns-test.sh" "$0" --inside "$@"
fi
shift
pairs=${1:-1000}
rate=${2:-100}
format=${3:-folder}
case "$format" in folder|mcap|both) ;; *) echo "record_gige: FORMAT '$format': expected folder, mcap or both" >&2; exit 2;; esac
build=${BINOCLE_BUILD_DIR:-$here/build}
binocle="$build/bin/binocle"
export BINOCLE_PLUGIN_PATH="$build/lib/binocle/plugins"
work=$(mktemp -d)
cameras=""
cleanup() {
    for pid in $cameras; do kill "$pid" 2>/dev/null || true; done
    rm -rf "$work"
}
trap cleanup EXIT INT TERM
for a in 127.0.0.2 127.0.0.3; do
    arv-fake-gv-camera-0.8 -i "$a" -s "BENCH${a##*.}" >/dev/null 2>&1 &
    cameras="$cameras $!"
done
sleep 1

record() { # NAME SECONDS EXTRA-ARGS...: at most SECONDS, then Ctrl-C (a clean stop, summary written)
    name=$1
    seconds=$2
    shift 2
    timeout --foreground -s INT "$seconds" "$binocle" record "$here/configs/rigs/gige-two-cameras.yaml" --out "$work/$name" --frames "$pairs" --quiet \
        --set source.camera_left=127.0.0.2 --set source.camera_right=127.0.0.3 \
        --set source.width=640 --set source.height=480 --set source.trigger=free_run \
        --set source.frame_rate_hz="$rate" "$@" >"$work/$name.log" 2>&1 || true
}

echo "record_gige: $pairs pairs, two external fake cameras at $rate Hz, 640x480 Mono8; $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
if [ "$format" != mcap ]; then
    record before 30 --set source.socket_buffer_bytes=212992 --set source.buffers=8 --writer-threads 1 --when-behind wait
    record now 150
fi
if [ "$format" != folder ]; then
    record mcap 150 --format mcap
fi
python3 - "$work" <<'EOF'
import json, os, sys
work = sys.argv[1]
runs = {}
def size_of(folder):
    total = 0
    for root, _, files in os.walk(folder):
        total += sum(os.path.getsize(os.path.join(root, f)) for f in files)
    return total
for name in ("before", "now", "mcap"):
    if not os.path.exists(f"{work}/{name}.log"):
        continue
    try:
        s = json.load(open(f"{work}/{name}/summary.json"))
    except OSError:
        import os
        print(f"{name}: no summary ({os.listdir(work)}); log:\n" + open(f"{work}/{name}.log").read())
        continue
    runs[name] = s
    lost = s["lost"]
    sent = max(c.get("images_sent", 0) for c in lost.get("cameras", {}).values()) if lost.get("cameras") else 0
    print(f"{name:>6}: {s['status']}, {s['pairs_written']} pairs written of {s['pairs_taken']} taken in {s['seconds']:.1f} s "
          f"= {s['pairs_written_per_s']:.1f} pairs/s; writer: {s['writer']['threads']} thread(s), "
          f"{s['writer']['encode_ms_per_image']:.1f} ms encoding + {s['writer']['write_ms_per_image']:.1f} ms writing per image")
    for role, c in lost.get("cameras", {}).items():
        share = 100.0 * s["pairs_written"] / c["images_sent"] if c.get("images_sent") else 0
        print(f"        {role}: {c.get('images_sent')} images sent, {share:.1f} % of them in written pairs; lost "
              f"{c.get('lost_in_camera_or_transport')} in the camera or transport, {c.get('lost_in_pairing')} in pairing")
    print(f"        {lost['pairs_dropped_by_writer']} pairs dropped by the writers ({lost['when_writers_behind']} when behind)")
    size = size_of(f"{work}/{name}")
    if s["pairs_written"]:
        print(f"        {size / 1e6:.1f} MB written, {size / s['pairs_written'] / 1e3:.1f} kB per pair")
    if "error" in s:
        print(f"        error: {s['error']}")
if "before" in runs and "now" in runs and runs["before"]["pairs_written_per_s"] > 0:
    b, n = runs["before"], runs["now"]
    print(f" ratio: now / before = {n['pairs_written_per_s'] / b['pairs_written_per_s']:.2f}x pairs written per second")
if "now" in runs and "mcap" in runs and runs["now"]["pairs_written"] and runs["mcap"]["pairs_written"]:
    n, m = runs["now"], runs["mcap"]
    per = lambda name, s: size_of(f"{work}/{name}") / s["pairs_written"]
    print(f" ratio: mcap / folder = {m['pairs_written_per_s'] / n['pairs_written_per_s']:.2f}x pairs written per second, "
          f"{per('mcap', m) / per('now', n):.2f}x bytes per pair")
EOF
