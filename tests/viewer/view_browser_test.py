# SPDX-License-Identifier: MIT
# `binocle view` in a real browser: headless Chromium against the simulated rig, on
# loopback only. The page loads without console errors, frames arrive and change, a
# control re-creates the matcher, an invalid value shows the host's error, several
# browsers at once, token and Host guards, a snapshot; a screenshot is kept.
#
# usage: view_browser_test.py BINOCLE_CLI SOURCE_DIR OUT_DIR
import http.client
import json
import os
import re
import shutil
import subprocess
import sys
import threading
import time
import urllib.parse

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from browser_common import artifact_dir, console_errors, start_browser  # noqa: E402

cli, source_dir, out_dir = sys.argv[1:4]
shutil.rmtree(out_dir, ignore_errors=True)
os.makedirs(out_dir)
rig = os.path.join(source_dir, "configs/rigs/sim-videre.yaml")
failures = []


def check(condition, what):
    print(("ok   " if condition else "FAIL ") + what, flush=True)
    if not condition:
        failures.append(what)


def wait_for(predicate, timeout, what):
    end = time.time() + timeout
    while time.time() < end:
        value = predicate()
        if value:
            return value
        time.sleep(0.1)
    raise AssertionError(f"timed out after {timeout} s waiting for {what}")


# Bad values of the display's options are usage errors naming the option.
for option, value in (("--cloud-points", "0"), ("--display-fps", "0"), ("--cloud-fps", "0")):
    bad = subprocess.run([cli, "view", rig, option, value], capture_output=True, text=True, timeout=60)
    check(bad.returncode == 2 and option in bad.stderr, f"view {option} {value} is refused: {bad.stderr.strip()[:120]!r}")

# One sample per pixel: the test is about the page, not the renderer's antialiasing.
DISPLAY_FPS, CLOUD_POINTS = 8, 5000
view = subprocess.Popen([cli, "view", rig, "--port", "0", "--out", os.path.join(out_dir, "snapshots"),
                         "--set", "source.antialias=1", "--display-fps", str(DISPLAY_FPS),
                         "--cloud-points", str(CLOUD_POINTS)],
                        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
stderr_lines = []
threading.Thread(target=lambda: stderr_lines.extend(view.stderr), daemon=True).start()
line = view.stdout.readline()
match = re.search(r"open (http://127\.0\.0\.1:(\d+)/\?token=([0-9a-f]+))", line)
if not match:
    view.kill()
    sys.exit(f"binocle view printed no URL: {line!r} {''.join(stderr_lines)}")
url, port, token = match.group(1), int(match.group(2)), match.group(3)
print("view at", url, flush=True)


def request(method, path, host=None, body=None):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    headers = {"Host": host or f"127.0.0.1:{port}"}
    c.request(method, path, body=body, headers=headers)
    r = c.getresponse()
    data = r.read()
    c.close()
    return r.status, data


driver = None
try:
    # Guards, before any browser.
    check(request("GET", "/api/state")[0] == 403, "an API call without the token is refused (403)")
    check(request("GET", "/api/state?token=" + "0" * 32)[0] == 403, "an API call with a wrong token is refused")
    check(request("GET", f"/api/state?token={token}")[0] == 200, "an API call with the token is answered")
    check(request("GET", f"/?token={token}", host="attacker.example:80")[0] == 403,
          "a request whose Host is not local is refused (DNS rebinding)")
    check(request("GET", f"/api/state?token={token}", host=f"localhost:{port}")[0] == 200, "Host localhost is served")
    status, page = request("GET", "/")
    check(status == 200 and b"app.js" in page, "the page is served from the binary")
    check(not re.search(rb"(src|href)=\"https?://", page), "the page loads nothing from the network")

    driver = start_browser()
    driver.get(url)
    wait_for(lambda: driver.execute_script("return window.binocle.framesReceived") >= 1, 60, "the first frame")
    first = int(driver.find_element("id", "frame-counter").text)
    wait_for(lambda: int(driver.find_element("id", "frame-counter").text) > first + 2, 30, "the frame counter to advance")
    check(True, f"the frame counter advances (from {first})")

    # The disparity image's pixels, summed in the page (each panel is a canvas the page
    # draws the frame's decoded image on).
    checksum_js = """
        const done = arguments[arguments.length - 1];
        const c = document.getElementById('img-disparity');
        const run = () => {
          const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
          let h = 0; for (let i = 0; i < d.length; i++) h = (h * 31 + d[i]) >>> 0;
          done([window.binocle.drawn.disparity, h, c.width, c.height]);
        };
        const wait = () => (window.binocle.drawn.disparity !== undefined ? run() : setTimeout(wait, 50));
        wait();
    """
    seq_a, sum_a, w, h = driver.execute_async_script(checksum_js)
    wait_for(lambda: int(driver.find_element("id", "sequence").text) > seq_a, 30, "another frame")
    seq_b, sum_b, _, _ = driver.execute_async_script(checksum_js)
    check(w == 320 and h == 240, f"the disparity image is 320 x 240 ({w} x {h})")
    check(seq_b != seq_a and sum_b != sum_a, f"the disparity image changes between frames {seq_a} and {seq_b}")

    for name in ("left", "right", "top", "front", "side"):
        # Drawn once a frame's images are decoded: the canvas then has its size and a sequence.
        size = wait_for(lambda: (lambda s: s if s[2] is not None else None)(driver.execute_script(
            f"const c = document.getElementById('img-{name}'); return [c.width, c.height, window.binocle.drawn['{name}']];")),
            10, f"panel {name}'s image")
        check(size[0] > 0 and size[1] > 0, f"panel {name} shows an image ({size[0]} x {size[1]})")
    cloud_note = driver.find_element("id", "cloud-note").text
    check("points shown" in cloud_note and "ground frame" in cloud_note, f"the 3D view draws the cloud: {cloud_note!r}")
    shown_points = int(cloud_note.split()[0])
    # What the WebGL view put on the screen (a WebGL canvas cannot be read back once
    # composited): the browser's own screenshot of it, its pixels counted in the page.
    # Points are coloured by height; the clear colour and the grid's grey are not.
    x, y, w, h = driver.execute_script(
        "const r = document.getElementById('cloud').getBoundingClientRect(); return [r.x, r.y, r.width, r.height];")
    png = driver.execute_cdp_cmd("Page.captureScreenshot", {
        "format": "png", "captureBeyondViewport": True,
        "clip": {"x": x, "y": y + driver.execute_script("return window.scrollY"), "width": w, "height": h, "scale": 1}})["data"]
    coloured = driver.execute_async_script("""
        const done = arguments[arguments.length - 1];
        const img = new Image();
        img.onload = () => {
          const c = document.createElement('canvas'); c.width = img.width; c.height = img.height;
          const g = c.getContext('2d'); g.drawImage(img, 0, 0);
          const d = g.getImageData(0, 0, c.width, c.height).data;
          let n = 0;
          for (let i = 0; i < d.length; i += 4) {
            const r = d[i], gr = d[i + 1], b = d[i + 2];
            if (Math.max(r, gr, b) - Math.min(r, gr, b) > 40) n++;  // not a grey nor the dark blue-grey clear colour
          }
          done(n);
        };
        img.src = 'data:image/png;base64,' + arguments[0];
    """, png)
    check(coloured > 200, f"the WebGL view shows the cloud's points ({coloured} coloured pixels)")
    check(0 < shown_points <= CLOUD_POINTS < driver.execute_script("return window.binocle.lastHeader.points"),
          f"--cloud-points bounds the 3D view: {shown_points} of "
          f"{driver.execute_script('return window.binocle.lastHeader.points')} points")
    # --display-fps bounds what a page gets (an upper bound: a busy machine only lowers it).
    got0, t0 = driver.execute_script("return window.binocle.framesReceived"), time.time()
    time.sleep(3)
    got1, t1 = driver.execute_script("return window.binocle.framesReceived"), time.time()
    check(got1 - got0 <= DISPLAY_FPS * (t1 - t0) + 1,
          f"--display-fps {DISPLAY_FPS}: the page got {got1 - got0} frames in {t1 - t0:.1f} s")
    figures = driver.find_element("id", "figures").text
    check("eta_3d_percent" in figures and "bad_" in figures and "valid pixels" in figures and "match" in figures,
          "the figures show stage times, valid pixels and every evaluator's metrics")
    check("frames:" in driver.find_element("id", "source-stats").text, "the source's statistics are shown")
    controls = driver.execute_script(
        "return Array.from(document.querySelectorAll('#controls .control')).map(c => c.dataset.key)")
    check("matcher.num_disparities" in controls and "matcher.mode" in controls and "source.noise_sigma" in controls,
          f"controls come from the plugins' settings tables ({len(controls)} controls)")
    check(driver.execute_script("return document.querySelector('#ctl-matcher\\\\.block_size input[type=range]') !== null"),
          "an INT with min and max is a slider")
    check(driver.execute_script("return document.querySelector('#ctl-evaluators\\\\.0\\\\.write_views input[type=checkbox]') !== null"),
          "a BOOL is a switch")
    check(driver.execute_script("return document.querySelector('#ctl-matcher\\\\.mode select') !== null"),
          "an ENUM is a choice")

    # Moving num_disparities re-creates the matcher: the plugin's own answer changes.
    before = driver.execute_script("return window.binocle.lastHeader.matcher.num_disparities")
    set_js = """
        const input = document.querySelector(arguments[0]);
        input.value = arguments[1];
        input.dispatchEvent(new Event('change'));
    """
    driver.execute_script(set_js, "#ctl-matcher\\.num_disparities input[type=number]", "128")
    wait_for(lambda: driver.execute_script("return window.binocle.lastHeader.matcher.num_disparities") == 128, 90,
             "the matcher to report 128 disparities (replies: %s)" % driver.execute_script(
                 "return window.binocle.replies.map(r => r.type + ' ' + (r.message || r.last_change || ''))"))
    # The page's text follows within a second (it changes at most twice a second).
    figure_js = "return document.querySelector('#figures tr[data-figure=\"matcher range\"] td.value').textContent"
    shown = wait_for(lambda: (lambda t: t if "128" in t else None)(driver.execute_script(figure_js)), 5,
                     "the figures to show the new range")
    check(before == 64 and "128" in shown, f"num_disparities 64 -> 128 re-creates the matcher (figures: {shown!r})")
    check("--set matcher.num_disparities=128" in driver.find_element("id", "set-lines").get_attribute("value"),
          "the change is listed as a --set line")
    status, rig_yaml = request("GET", f"/api/rig.yaml?token={token}")
    check(status == 200 and b"num_disparities: 128" in rig_yaml, "the rig can be saved with the change")

    # An invalid value: the host's own message, the one --set would give.
    driver.execute_script(set_js, "#ctl-matcher\\.num_disparities input[type=number]", "100")
    message = wait_for(lambda: driver.find_element("id", "message").text, 20, "an error message")
    check("matcher.num_disparities" in message and "multiple of 16" in message and "100" in message,
          f"an invalid value shows the host's error: {message!r}")
    check(driver.execute_script("return window.binocle.lastHeader.matcher.num_disparities") == 128,
          "the refused value leaves the matcher as it was")

    # Several browsers: a second tab gets frames; closing it costs the first nothing.
    main_tab = driver.current_window_handle
    driver.switch_to.new_window("tab")
    driver.get(url)
    wait_for(lambda: driver.execute_script("return window.binocle.framesReceived") >= 2, 30, "frames in a second tab")
    check(True, "a second browser receives frames at the same time")
    driver.close()
    driver.switch_to.window(main_tab)
    got = driver.execute_script("return window.binocle.framesReceived")
    wait_for(lambda: driver.execute_script("return window.binocle.framesReceived") > got + 2, 30,
             "frames after the other browser went away")
    check(True, "after the second browser went away the first still gets frames")

    # Pause and step.
    driver.find_element("id", "pause").click()
    wait_for(lambda: driver.execute_script("return window.binocle.state.paused"), 30, "paused")
    time.sleep(1.0)
    processed = lambda: json.loads(request("GET", f"/api/state?token={token}")[1])["frames_processed"]  # noqa: E731
    held = processed()
    time.sleep(1.5)
    check(processed() == held, "pause holds the pipeline")
    driver.find_element("id", "step").click()
    wait_for(lambda: int(driver.find_element("id", "frame-counter").text) == held + 1, 60, "the stepped frame on the page")
    check(processed() == held + 1, "step processes one frame, and the page shows it")

    # Snapshot: that frame's outputs, like `binocle run`.
    driver.find_element("id", "snapshot").click()
    note = wait_for(lambda: "written to" in driver.find_element("id", "message").text and
                    driver.find_element("id", "message").text, 20, "the snapshot's message")
    snap = os.path.join(out_dir, "snapshots")
    files = sorted(os.listdir(snap)) if os.path.isdir(snap) else []
    check(any(f.startswith("disparity_") and f.endswith(".png") for f in files) and
          any(f.startswith("cloud_") for f in files) and any(f.startswith("frame_") for f in files) and
          any(f.startswith("view_top_") for f in files), f"snapshot writes the frame's outputs: {files}")

    shot = os.path.join(artifact_dir(), "viewer.png")
    driver.save_screenshot(shot)
    print("screenshot:", shot)
    errors = console_errors(driver)
    check(not errors, f"no console errors ({errors})")
finally:
    if driver:
        driver.quit()
    view.terminate()
    try:
        out, _ = view.communicate(timeout=15)
    except subprocess.TimeoutExpired:
        view.kill()
        out, _ = view.communicate()
    print("binocle view said:", out.strip(), "".join(stderr_lines[-5:]).strip())

check(view.returncode == 0, f"binocle view ends cleanly on SIGTERM (exit {view.returncode})")
if failures:
    print(f"{len(failures)} check(s) failed")
    sys.exit(1)
print("all checks passed")
