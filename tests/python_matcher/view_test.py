# SPDX-License-Identifier: MIT
# `binocle view` with the example's rig (a matcher written in Python, isolated): it
# starts, processes frames, shows the Python matcher's settings as controls, and a
# snapshot writes the disparity. Loopback only (run inside scripts/netns-test.sh).
import base64
import json
import os
import re
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import CLI, EXAMPLE  # noqa: E402


def first_frame(port, token, seconds):
    """Opens the page's WebSocket (frames are encoded for a viewer) and waits for a
    binary message, a frame; returns its size."""
    s = socket.create_connection(("127.0.0.1", port), timeout=seconds)
    key = base64.b64encode(os.urandom(16)).decode()
    s.sendall((f"GET /ws?token={token} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nUpgrade: websocket\r\n"
               f"Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n\r\n").encode())
    stream = s.makefile("rb")
    if b" 101 " not in stream.readline():
        sys.exit("the page's WebSocket did not open")
    while stream.readline() not in (b"\r\n", b""):
        pass
    while True:
        b0, b1 = stream.read(2)
        n = b1 & 0x7F
        if n >= 126:
            n = int.from_bytes(stream.read(2 if n == 126 else 8), "big")
        stream.read(n)
        if b0 & 0x0F == 2:  # binary: a frame
            s.close()
            return n


def request(port, path, body=None, token=None):
    """(status, body) of a GET, or of a POST with the token header when body is given."""
    headers = {"X-Binocle-Token": token} if token else {}
    data = body.encode() if body is not None else None
    with urllib.request.urlopen(urllib.request.Request(f"http://127.0.0.1:{port}{path}", data=data, headers=headers),
                                timeout=30) as r:
        return r.status, r.read()


out = tempfile.mkdtemp(prefix="python-matcher-view-")
rig = os.path.join(EXAMPLE, "rig-aloe.yaml")
# A smaller search keeps each frame short on a loaded machine; the rig is otherwise as is.
view = subprocess.Popen([CLI, "view", rig, "--port", "0", "--out", out, "--set", "matcher.num_disparities=64"],
                        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
try:
    line = view.stdout.readline()
    m = re.search(r"open http://127\.0\.0\.1:(\d+)/\?token=([0-9a-f]+)", line)
    if not m:
        view.kill()
        sys.exit(f"binocle view printed no URL: {line!r} {view.stderr.read()[-2000:]}")
    port, token = int(m.group(1)), m.group(2)
    print(f"first frame received: {first_frame(port, token, 240)} bytes", flush=True)
    deadline = time.monotonic() + 240
    state = {}
    while time.monotonic() < deadline:
        status, body = request(port, f"/api/state?token={token}")
        state = json.loads(body)
        if state.get("frames_processed", 0) >= 1:
            break
        time.sleep(1)
    if state.get("frames_processed", 0) < 1:
        sys.exit(f"no frame processed in 240 s: {state.get('status')} {state.get('error')}")
    controls = json.dumps(state["blocks"])
    if "window_px" not in controls or "uniqueness_percent" not in controls:
        sys.exit(f"the Python matcher's settings are not among the page's controls: {controls[:400]}")
    # The first frame shown may come a little after the first processed.
    for _ in range(60):
        status, body = request(port, "/api/command", body='{"op":"snapshot"}', token=token)
        reply = json.loads(body)
        if reply.get("type") == "snapshot":
            break
        time.sleep(1)
    if status != 200 or reply.get("type") != "snapshot" or not any(f.startswith("disparity_") for f in os.listdir(out)):
        sys.exit(f"the snapshot wrote no disparity: {status} {reply}")
    print(f"ok: {state['frames_processed']} frames processed, snapshot {reply.get('files')}")
finally:
    view.terminate()
    try:
        view.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        view.kill()
    shutil.rmtree(out, ignore_errors=True)
