# SPDX-License-Identifier: MIT
# What watching costs: the pipeline's frame rate of `binocle view` with a browser showing
# every frame it can, against the same view with no browser open, in one run
# (alternating, several rounds, medians). Both rates are read the same way: the
# pipeline's frame counter (/api/state) over a fixed window after a warm-up.
# Where the CPU went is measured in the same windows (/proc): the view process (pipeline
# + encoder + server), the browser (every process under chromedriver), and the whole
# machine (other users of a shared box included), in cores (1.0 = one core busy).
#
# usage: /usr/bin/python3 bench/view_overhead.py [--rig RIG] [--rounds 3] [--seconds 10]
#        [--set KEY=VALUE]... [--view-arg=--display-fps=5]... [--page-draws-nothing] [--page-without-cloud]
#        [--page-script JS]... [--swiftshader-compositing]
#        [--json FILE]
#   BINOCLE_CLI (default build/bin/binocle), BINOCLE_PLUGIN_PATH (absolute) as for the CLI.
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
parser.add_argument("--view-arg", action="append", default=[], help="more arguments for `binocle view`")
parser.add_argument("--json", help="also write the medians and every round here")
parser.add_argument("--page-draws-nothing", action="store_true",
                    help="the page takes and acknowledges every frame but draws none: the viewer's own cost "
                         "(copy, encoding, sending) without the browser's rendering")
parser.add_argument("--page-without-cloud", action="store_true",
                    help="the page draws everything but the 3D view: what the WebGL point view costs the browser")
parser.add_argument("--page-script", action="append", default=[],
                    help="JavaScript run in the page once it shows frames (e.g. 'showFigures = function () {};'): "
                         "what one part of the page costs, by switching it off")
parser.add_argument("--swiftshader-compositing", action="store_true",
                    help="Chromium composites the page through SwiftShader too (a testing-only path; by default it "
                         "composites in software, as Chrome without a usable GPU does; WebGL is on SwiftShader either way)")
args = parser.parse_args()
cli = os.environ.get("BINOCLE_CLI", os.path.join(root, "build/bin/binocle"))
TICK = os.sysconf("SC_CLK_TCK")


def frames(port, token):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    c.request("GET", f"/api/state?token={token}")
    state = json.loads(c.getresponse().read())
    c.close()
    return state["frames_processed"], time.monotonic()


def cpu_seconds(pids):
    """User + system CPU seconds of these processes (every thread), as of now."""
    total = 0.0
    for pid in pids:
        try:
            with open(f"/proc/{pid}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
            total += (int(fields[11]) + int(fields[12])) / TICK
        except (OSError, IndexError, ValueError):
            pass  # ended meanwhile
    return total


def descendants(pid):
    children = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as f:
                    ppid = int(f.read().rsplit(")", 1)[1].split()[1])
                children.setdefault(ppid, []).append(int(entry))
            except (OSError, IndexError, ValueError):
                pass
    out, todo = [], [pid]
    while todo:
        p = todo.pop()
        out.append(p)
        todo.extend(children.get(p, []))
    return out


def process_kind(pid):
    """Chromium's process type (renderer, gpu-process, utility, ...; 'browser' for the main
    one, 'chromedriver' for the driver), to say which part of the browser takes the CPU."""
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as f:
            # Chromium's children rewrite their title: one string, arguments joined by spaces.
            argv = f.read().decode(errors="replace").replace("\0", " ").split()
    except OSError:
        return "ended"
    if argv and argv[0].endswith("chromedriver"):
        return "chromedriver"
    for a in argv:
        if a.startswith("--type="):
            kind = a[len("--type="):]
            if kind == "utility":
                sub = [x for x in argv if x.startswith("--utility-sub-type=")]
                kind += ":" + (sub[0].split(".")[-1] if sub else "?")
            return kind
    return "browser"


def machine_busy():
    """(busy, total) jiffies of all CPUs."""
    with open("/proc/stat") as f:
        v = [int(x) for x in f.readline().split()[1:]]
    idle = v[3] + v[4]
    return sum(v) - idle, sum(v)


def measure(with_browser):
    cmd = [cli, "view", args.rig, "--port", "0", "--out", "/tmp/binocle-view-bench"] + args.view_arg
    for s in args.set:
        cmd += ["--set", s]
    view = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    m = re.search(r"(http://127\.0\.0\.1:(\d+)/\?token=([0-9a-f]+))", view.stdout.readline())
    url, port, token = m.group(1), int(m.group(2)), m.group(3)
    driver = None
    try:
        if with_browser:
            driver = start_browser(swiftshader_compositing=args.swiftshader_compositing)
            driver.get(url)
            end = time.time() + 60
            while driver.execute_script("return window.binocle.framesReceived") < 1 and time.time() < end:
                time.sleep(0.1)
            if args.page_draws_nothing:  # the page's frame handler, replaced by a count and the acknowledgement
                driver.execute_script("onFrame = function () { window.binocle.framesReceived += 1; send({op: 'shown'}); };")
            if args.page_without_cloud:  # the 3D view keeps its first cloud
                driver.execute_script("cloudView.setPoints = function () {};")
            for script in args.page_script:
                driver.execute_script(script)
        time.sleep(args.warmup)
        browser = descendants(driver.service.process.pid) if driver else []
        n0, t0 = frames(port, token)
        v0, b0, m0 = cpu_seconds([view.pid]), cpu_seconds(browser), machine_busy()
        kinds = {pid: process_kind(pid) for pid in browser}
        k0 = {pid: cpu_seconds([pid]) for pid in browser}
        page = "return [window.binocle.framesReceived, window.binocle.showMs]"
        s0, ms0 = driver.execute_script(page) if driver else (0, 0)
        time.sleep(args.seconds)
        n1, t1 = frames(port, token)
        v1, b1, m1 = cpu_seconds([view.pid]), cpu_seconds(browser), machine_busy()
        s1, ms1 = driver.execute_script(page) if driver else (0, 0)
        by_kind = {}
        for pid in browser:
            by_kind[kinds[pid]] = by_kind.get(kinds[pid], 0.0) + cpu_seconds([pid]) - k0[pid]
        shown = s1 - s0
        load = os.getloadavg()[0]
    finally:
        if driver:
            driver.quit()
        view.terminate()
        view.wait(timeout=20)
    dt = t1 - t0
    cores = os.cpu_count()
    busy = cores * (m1[0] - m0[0]) / max(1, m1[1] - m0[1])
    return {"pipeline_fps": (n1 - n0) / dt, "page_fps": shown / dt, "view_cores": (v1 - v0) / dt,
            "browser_cores": (b1 - b0) / dt,
            "browser_cores_by_process": {k: round(v / dt, 3) for k, v in sorted(by_kind.items())} if driver else {}, "page_show_ms": (ms1 - ms0) / shown if shown else 0, "machine_busy_cores": busy,
            "others_cores": max(0.0, busy - (v1 - v0) / dt - (b1 - b0) / dt), "load_1min": load}


rounds = []
for r in range(args.rounds):
    # Alternate which goes first, so that a trend in the machine's load hits both alike.
    order = (False, True) if r % 2 == 0 else (True, False)
    got = {w: measure(w) for w in order}
    a, b = got[False], got[True]
    rounds.append({"without": a, "with": b})
    print(f"round {r + 1}: pipeline {a['pipeline_fps']:.1f} fps without a browser, {b['pipeline_fps']:.1f} fps with one "
          f"(page shows {b['page_fps']:.1f} fps; view process {a['view_cores']:.2f} -> {b['view_cores']:.2f} cores, "
          f"browser {b['browser_cores']:.2f} cores, others on the machine {a['others_cores']:.2f} / "
          f"{b['others_cores']:.2f} cores, load {a['load_1min']:.1f} / {b['load_1min']:.1f})", flush=True)


def med(which, key):
    return statistics.median(x[which][key] for x in rounds)


ratios = [x["with"]["pipeline_fps"] / x["without"]["pipeline_fps"] for x in rounds if x["without"]["pipeline_fps"] > 0]
result = {"rig": os.path.basename(args.rig), "view_args": args.view_arg, "page_draws_nothing": args.page_draws_nothing,
          "page_without_cloud": args.page_without_cloud, "page_script": args.page_script,
          "swiftshader_compositing": args.swiftshader_compositing, "rounds": args.rounds, "window_s": args.seconds,
          "cores": os.cpu_count(),
          "fps_without_browser": round(med("without", "pipeline_fps"), 2),
          "fps_with_browser": round(med("with", "pipeline_fps"), 2),
          "page_fps": round(med("with", "page_fps"), 2),
          "median_ratio": round(statistics.median(ratios), 3) if ratios else None,
          "drop_percent": round(100 * (1 - statistics.median(ratios)), 1) if ratios else None,
          "view_cores_without": round(med("without", "view_cores"), 2),
          "view_cores_with": round(med("with", "view_cores"), 2),
          "browser_cores": round(med("with", "browser_cores"), 2),
          "browser_cpu_ms_per_page_frame": round(1000 * med("with", "browser_cores") / med("with", "page_fps"), 1)
          if med("with", "page_fps") > 0 else None,
          "page_show_ms": round(med("with", "page_show_ms"), 1),
          "browser_cores_by_process": {k: round(statistics.median(x["with"]["browser_cores_by_process"].get(k, 0) for x in rounds), 3)
                                       for k in rounds[0]["with"]["browser_cores_by_process"]},
          "others_cores_without": round(med("without", "others_cores"), 2),
          "others_cores_with": round(med("with", "others_cores"), 2)}
print(json.dumps(result))
if args.json:
    with open(args.json, "w") as f:
        json.dump({"medians": result, "rounds": rounds}, f, indent=1)
