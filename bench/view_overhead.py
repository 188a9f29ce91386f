# SPDX-License-Identifier: MIT
# What watching costs: the pipeline's frame rate of `binocle view` with a browser showing
# every frame it can, against the same view with no browser open, in one run
# (alternating, several rounds, medians). Both rates are read the same way: the
# pipeline's frame counter (/api/state) over a fixed window after a warm-up.
#
# usage: /usr/bin/python3 bench/view_overhead.py [--rig RIG] [--rounds 3] [--seconds 10] [--set KEY=VALUE]...
#   BINOCLE_CLI (default build/bin/binocle), BINOCLE_PLUGIN_PATH as for the CLI.
# Run it inside scripts/netns-test.sh to keep everything on loopback.
import argparse
import http.client
import json
import os
import re
import statistics
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "viewer"))
from browser_common import start_browser  # noqa: E402

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
parser = argparse.ArgumentParser()
parser.add_argument("--rig", default=os.path.join(root, "configs/rigs/sim-videre.yaml"))
parser.add_argument("--rounds", type=int, default=3)
parser.add_argument("--seconds", type=float, default=10)
parser.add_argument("--warmup", type=float, default=3)
parser.add_argument("--set", action="append", default=[])
args = parser.parse_args()
cli = os.environ.get("BINOCLE_CLI", os.path.join(root, "build/bin/binocle"))


def frames(port, token):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    c.request("GET", f"/api/state?token={token}")
    state = json.loads(c.getresponse().read())
    c.close()
    return state["frames_processed"], time.monotonic()


def measure(with_browser):
    cmd = [cli, "view", args.rig, "--port", "0", "--out", "/tmp/binocle-view-bench"]
    for s in args.set:
        cmd += ["--set", s]
    view = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    m = re.search(r"(http://127\.0\.0\.1:(\d+)/\?token=([0-9a-f]+))", view.stdout.readline())
    url, port, token = m.group(1), int(m.group(2)), m.group(3)
    driver = None
    shown = 0
    try:
        if with_browser:
            driver = start_browser()
            driver.get(url)
            end = time.time() + 60
            while driver.execute_script("return window.binocle.framesReceived") < 1 and time.time() < end:
                time.sleep(0.1)
        time.sleep(args.warmup)
        n0, t0 = frames(port, token)
        s0 = driver.execute_script("return window.binocle.framesReceived") if driver else 0
        time.sleep(args.seconds)
        n1, t1 = frames(port, token)
        if driver:
            shown = driver.execute_script("return window.binocle.framesReceived") - s0
    finally:
        if driver:
            driver.quit()
        view.terminate()
        view.wait(timeout=20)
    return (n1 - n0) / (t1 - t0), shown / (t1 - t0)


without, with_, displayed = [], [], []
for r in range(args.rounds):
    a, _ = measure(False)
    b, shown = measure(True)
    without.append(a)
    with_.append(b)
    displayed.append(shown)
    print(f"round {r + 1}: pipeline {a:.1f} fps without a browser, {b:.1f} fps with one (page shows {shown:.1f} fps)",
          flush=True)
fa, fb = statistics.median(without), statistics.median(with_)
print(json.dumps({"rig": os.path.basename(args.rig), "rounds": args.rounds, "window_s": args.seconds,
                  "fps_without_browser": round(fa, 2), "fps_with_browser": round(fb, 2),
                  "page_fps": round(statistics.median(displayed), 2),
                  "ratio": round(fb / fa, 3), "drop_percent": round(100 * (1 - fb / fa), 1)}))
