# SPDX-License-Identifier: MIT
# `binocle view` probed from outside as an attacker on the same machine would (issue 24):
# oversized keys and values, resource limits and paths from the page, cross-origin POSTs
# and WebSockets, planted symlinks, a non-reading client, a connection flood with few
# file descriptors, a Host flood against the log, binds beyond loopback, commands while
# snapshots run. Loopback only (run inside scripts/netns-test.sh); prints the figures.
#
# usage: view_guard_test.py BINOCLE_CLI SOURCE_DIR OUT_DIR
import base64
import http.client
import json
import os
import re
import resource
import shutil
import socket
import statistics
import struct
import subprocess
import sys
import time

cli, source_dir, out_dir = sys.argv[1:4]
shutil.rmtree(out_dir, ignore_errors=True)
os.makedirs(out_dir)
failures = []


def check(condition, what):
    print(("ok   " if condition else "FAIL ") + what, flush=True)
    if not condition:
        failures.append(what)


# A rig folder of its own (rigs/ and scenes/), a secret beside it, outside.
rig_dir = os.path.join(out_dir, "rig")
os.makedirs(os.path.join(rig_dir, "rigs"))
shutil.copytree(os.path.join(source_dir, "configs/scenes"), os.path.join(rig_dir, "scenes"))
with open(os.path.join(source_dir, "configs/rigs/sim-videre.yaml")) as f:
    rig_text = f.read()
rig = os.path.join(rig_dir, "rigs", "rig.yaml")
with open(rig, "w") as f:
    # A name no header may carry as is.
    f.write(rig_text.replace("name: sim-videre", 'name: "evil\\r\\nSet-Cookie: a=b"'))
secret = os.path.join(out_dir, "secret.yaml")
with open(secret, "w") as f:
    f.write("SECRET-FIRST-LINE: 1\n")
snap_dir = os.path.join(out_dir, "snapshots")
os.makedirs(snap_dir)
victim = os.path.join(out_dir, "victim.txt")
with open(victim, "w") as f:
    f.write("untouched")


# ---- A WebSocket client in a few lines (no library on this machine has one) ----------
def ws_open(port, token, origin=None, path=None):
    s = socket.create_connection(("127.0.0.1", port), timeout=20)
    key = base64.b64encode(os.urandom(16)).decode()
    lines = [f"GET {path or '/ws?token=' + token} HTTP/1.1", f"Host: 127.0.0.1:{port}", "Upgrade: websocket",
             "Connection: Upgrade", f"Sec-WebSocket-Key: {key}", "Sec-WebSocket-Version: 13"]
    if origin:
        lines.append(f"Origin: {origin}")
    s.sendall(("\r\n".join(lines) + "\r\n\r\n").encode())
    head = b""
    while b"\r\n\r\n" not in head:
        chunk = s.recv(1)
        if not chunk:
            break
        head += chunk
    status = int(head.split(b" ")[1]) if head.startswith(b"HTTP/1.1 ") else 0
    return s, status


def ws_send(s, text):
    payload = text.encode() if isinstance(text, str) else text
    mask = os.urandom(4)
    n = len(payload)
    header = bytes([0x81])
    if n < 126:
        header += bytes([0x80 | n])
    elif n < 65536:
        header += bytes([0x80 | 126]) + struct.pack(">H", n)
    else:
        header += bytes([0x80 | 127]) + struct.pack(">Q", n)
    masked = bytes(b ^ mask[i % 4] for i, b in enumerate(payload))
    s.sendall(header + mask + masked)


def recv_exact(s, n):
    out = b""
    while len(out) < n:
        chunk = s.recv(n - len(out))
        if not chunk:
            raise ConnectionError("closed")
        out += chunk
    return out


def ws_frame(s):
    b0, b1 = recv_exact(s, 2)
    n = b1 & 0x7F
    if n == 126:
        n = struct.unpack(">H", recv_exact(s, 2))[0]
    elif n == 127:
        n = struct.unpack(">Q", recv_exact(s, 8))[0]
    return bool(b0 & 0x80), b0 & 0x0F, recv_exact(s, n)


def ws_recv(s):
    """One whole message: a server may fragment it (Beast does past its write buffer)."""
    fin, op, data = ws_frame(s)
    while not fin:
        fin, _, more = ws_frame(s)  # continuation frames (op 0)
        data += more
    return op, data


def ws_reply(s, command, timeout=30):
    """Sends a command; returns the first reply that is not a state, a frame or a ping."""
    ws_send(s, json.dumps(command))
    end = time.time() + timeout
    while time.time() < end:
        op, data = ws_recv(s)
        if op == 1:
            msg = json.loads(data)
            if msg.get("type") not in ("state", "hello"):
                return msg
        elif op == 8:
            raise ConnectionError("closed by the server")
    raise TimeoutError(f"no reply to {command}")


def start_view(*extra, preexec=None):
    log = open(os.path.join(out_dir, f"view-{len(os.listdir(out_dir))}.log"), "w+")
    # Paced at 5 Hz: the probe is about the server, not the pipeline, on a shared machine.
    p = subprocess.Popen([cli, "view", rig, "--port", "0", "--out", snap_dir, "--set", "source.antialias=1",
                          "--set", "source.pace=true", "--set", "source.frame_rate_hz=5", *extra],
                         stdout=subprocess.PIPE, stderr=log, text=True, preexec_fn=preexec)
    line = p.stdout.readline()
    m = re.search(r"open http://127\.0\.0\.1:(\d+)/\?token=([0-9a-f]+)", line)
    if not m:
        p.kill()
        log.seek(0)
        sys.exit(f"binocle view printed no URL: {line!r} {log.read()[-2000:]}")
    return p, int(m.group(1)), m.group(2), log


def stop_view(p):
    p.terminate()
    try:
        p.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        p.kill()


def request(port, method, path, body=None, headers=None):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=20)
    h = {"Host": f"127.0.0.1:{port}"}
    h.update(headers or {})
    c.request(method, path, body=body, headers=h)
    r = c.getresponse()
    data = r.read()
    c.close()
    return r.status, data, r


def rss_mb(pid):
    with open(f"/proc/{pid}/status") as f:
        return int(re.search(r"VmRSS:\s+(\d+)", f.read()).group(1)) / 1024


def cpu_s(pid):
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


# ---- Binds beyond loopback need the user's word --------------------------------------
refused = subprocess.run([cli, "view", rig, "--bind", "0.0.0.0", "--port", "0"], capture_output=True, text=True, timeout=60)
check(refused.returncode != 0 and "--allow-remote" in refused.stderr and "every network" in refused.stderr,
      f"--bind 0.0.0.0 without --allow-remote is refused before binding: {refused.stderr.strip()[-160:]!r}")

view, port, token, log = start_view()
try:
    if os.geteuid() == 0:
        time.sleep(0.5)
        log.seek(0)
        check("running as root" in log.read(), "running as root is warned about")

    ws, status = ws_open(port, token)
    check(status == 101, "the page's WebSocket opens with the token")

    # Keys: 200 KB (the crash) closes that socket at the message cap; 20 KB (14 s and
    # 680 MB before) is refused at once.
    big, _ = ws_open(port, token)
    huge_key = ".".join(["a"] * 100000)
    ws_send(big, json.dumps({"op": "set", "key": huge_key, "value": "1"}))
    try:
        while True:
            op, _ = ws_recv(big)
            if op == 8:
                break
        closed = True
    except (ConnectionError, socket.timeout, OSError):
        closed = True
    check(closed and view.poll() is None, "a 200 KB key closes that WebSocket at the message cap; the view lives")
    t0 = time.time()
    r = ws_reply(ws, {"op": "set", "key": ".".join(["a"] * 10000), "value": "1"})
    key_ms = (time.time() - t0) * 1000
    check(r["type"] == "error" and "bytes long" in r["message"] and len(r["message"]) < 400,
          f"a 20 KB key is refused in {key_ms:.0f} ms: {r['message'][:100]!r}")

    # Resource limits and framework keys are not page controls.
    r = ws_reply(ws, {"op": "set", "key": "matcher.max_memory_mb", "value": "1048576"})
    check(r["type"] == "error" and "resource limit" in r["message"], f"max_memory_mb from the page: {r['message'][:90]!r}")
    r = ws_reply(ws, {"op": "set", "key": "runtime.matcher_instances", "value": "64"})
    check(r["type"] == "error" and "plugin settings only" in r["message"], "runtime.* from the page is refused")

    # Paths from the page stay inside the rig's folders and are never quoted.
    for path in ("/etc/shadow", secret, "../../secret.yaml", "../scenes/../../../secret.yaml"):
        r = ws_reply(ws, {"op": "set", "key": "source.scene", "value": path})
        check(r["type"] == "error" and "inside the rig's folders" in r["message"] and "SECRET" not in r["message"]
              and "root:" not in r["message"], f"source.scene={path} is refused, naming the path only")
    os.symlink(secret, os.path.join(rig_dir, "scenes", "planted.yaml"))
    r = ws_reply(ws, {"op": "set", "key": "source.scene", "value": "../scenes/planted.yaml"})
    check(r["type"] == "error" and "SECRET" not in json.dumps(r), "a link in the rig's folder leading out is refused")
    r = ws_reply(ws, {"op": "set", "key": "source.scene", "value": "../scenes/e1_panel.yaml"})
    check(r["type"] == "accepted", f"a scene inside the rig's folders is accepted ({r['type']})")

    # Values: capped, and a client that never reads holds no pile of states.
    r = ws_reply(ws, {"op": "set", "key": "evaluators.0.object", "value": "x" * 60000})
    check(r["type"] == "error" and "at most 4096" in r["message"], "a 60 KB value is refused")
    idle, _ = ws_open(port, token)  # never reads
    idle.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    before = rss_mb(view.pid)
    for i in range(250):
        r = ws_reply(ws, {"op": "set", "key": "source.noise_sigma", "value": str(1 + (i % 7) * 0.25)})
    grown = rss_mb(view.pid) - before
    check(grown < 100, f"250 accepted changes with a client that never reads: RSS {before:.0f} MB, +{grown:.0f} MB")

    # Anti-forgery: the form a cross-origin page can send is not obeyed.
    paused_before = json.loads(request(port, "GET", f"/api/state?token={token}")[1])["paused"]
    status, _, _ = request(port, "POST", f"/api/command?token={token}", body='{"op":"pause"}',
                           headers={"Content-Type": "text/plain", "Origin": "http://evil.example"})
    check(status == 403, f"a cross-origin text/plain POST with the URL's token is refused ({status})")
    status, _, _ = request(port, "POST", "/api/command", body='{"op":"pause"}',
                           headers={"X-Binocle-Token": token, "Origin": f"http://127.0.0.1:{port + 1}"})
    check(status == 403, "a POST from another port's origin is refused")
    check(json.loads(request(port, "GET", f"/api/state?token={token}")[1])["paused"] == paused_before,
          "neither changed anything")
    status, body, _ = request(port, "POST", "/api/command", body='{"op":"resume"}', headers={"X-Binocle-Token": token})
    check(status == 200 and json.loads(body)["type"] == "ok", "a POST with the token header is obeyed")
    _, status = ws_open(port, token, origin=f"http://127.0.0.1:{port + 1}")
    check(status == 403, "a WebSocket from another port's origin is refused")

    # Save rig: the name cannot add a header.
    status, body, resp = request(port, "GET", f"/api/rig.yaml?token={token}")
    disposition = resp.getheader("Content-Disposition") or ""
    check(status == 200 and resp.getheader("Set-Cookie") is None and "\r" not in disposition and
          re.fullmatch(r'attachment; filename="[A-Za-z0-9._-]+"', disposition) is not None,
          f"Save rig's file name is made safe: {disposition!r}")

    # Snapshots: links planted at the names they write are replaced, not followed; the
    # I/O thread answers while they run (figures, not limits: the machine is shared).
    for seq in range(0, 400):
        for name in (f"disparity_{seq:06d}.png", f"frame_{seq:06d}.json", f"view_top_{seq:06d}.png"):
            os.symlink(victim, os.path.join(snap_dir, name))
    for _ in range(5):
        r = ws_reply(ws, {"op": "snapshot"})
        if r["type"] == "snapshot":
            break
        time.sleep(1)
    with open(victim) as f:
        check(f.read() == "untouched", "a snapshot writes through no link planted in --out")
    written = [f for f in os.listdir(snap_dir) if not os.path.islink(os.path.join(snap_dir, f))]
    check(r["type"] == "snapshot" and any(f.startswith("disparity_") for f in written),
          f"the snapshot wrote files of its own ({len(written)})")
    latencies = []
    snapper, _ = ws_open(port, token)
    for _ in range(20):
        ws_send(snapper, '{"op":"snapshot"}')
    for _ in range(40):
        t0 = time.time()
        status, _, _ = request(port, "GET", f"/api/state?token={token}")
        latencies.append((time.time() - t0) * 1000)
    latencies.sort()
    check(status == 200, f"/api/state while 20 snapshots run: median {statistics.median(latencies):.1f} ms, "
                         f"p95 {latencies[int(0.95 * len(latencies))]:.1f} ms")

    # The log: a flood of refused Hosts costs a few lines.
    log.flush()
    size0 = os.path.getsize(log.name)
    t0 = time.time()
    for _ in range(30):
        c = socket.create_connection(("127.0.0.1", port), timeout=10)
        for _ in range(50):
            c.sendall(f"GET / HTTP/1.1\r\nHost: {'h' * 7000}\r\n\r\n".encode())
        c.shutdown(socket.SHUT_WR)
        while c.recv(65536):
            pass
        c.close()
    grown = os.path.getsize(log.name) - size0
    check(grown < 20000, f"1500 refused 7 KB Hosts in {time.time() - t0:.1f} s add {grown} bytes of log")
    check(view.poll() is None, "the view still runs")
finally:
    stop_view(view)
check(view.returncode == 0, f"binocle view ends cleanly on SIGTERM (exit {view.returncode})")
log.seek(0)
text = log.read()
check("SECRET" not in text, "the log never quotes the secret file")


# ---- Few file descriptors, 300 idle connections: no spin --------------------------------
def few_fds():
    resource.setrlimit(resource.RLIMIT_NOFILE, (96, 96))


view, port, token, log = start_view("--paused", preexec=few_fds)
try:
    time.sleep(1)
    sockets = []
    for _ in range(300):
        try:
            sockets.append(socket.create_connection(("127.0.0.1", port), timeout=5))
        except OSError:
            break
    time.sleep(1)
    c0, t0 = cpu_s(view.pid), time.time()
    time.sleep(4)
    busy = (cpu_s(view.pid) - c0) / (time.time() - t0)
    for s in sockets:
        s.close()
    check(busy < 0.5, f"with a 96-descriptor limit and {len(sockets)} idle connections the paused view uses "
                      f"{busy * 100:.0f} % of a core (a spinning accept loop takes a whole one)")
    status = 0
    for _ in range(50):
        try:
            status = request(port, "GET", f"/api/state?token={token}")[0]
            break
        except OSError:
            time.sleep(0.2)
    check(status == 200, "once they close, the view serves again")
    log.flush()
    check(os.path.getsize(log.name) < 20000, f"the refusals cost {os.path.getsize(log.name)} bytes of log")
finally:
    stop_view(view)

if failures:
    print(f"{len(failures)} check(s) failed")
    sys.exit(1)
print("all checks passed")
