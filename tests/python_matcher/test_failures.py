# SPDX-License-Identifier: MIT
# Python matchers that go wrong (the py_misbehaving fixture): every failure is a clear
# error naming the plugin, its file and what went wrong, and the run ends with its
# summary; a crash or a hang is contained by `isolation: process`.
import json
import os
import re
import shutil
import subprocess
import time

import pytest

from common import CLI, SIM_RIG, binocle, misbehaving, summary

FIXTURE = "binocle_py_misbehaving.py"


def failed_run(tmp_path, behaviour, isolated=False, extra=""):
    out = str(tmp_path / "out")
    started = time.monotonic()
    r = binocle("run", SIM_RIG, "--frames", "1", "--out", out, "--set", misbehaving(behaviour, isolated, extra))
    seconds = time.monotonic() - started
    assert r.returncode == 1, r.stdout + r.stderr
    s = summary(out)
    assert s["status"] == "failed", s
    return r.stderr, s["error"], seconds


@pytest.mark.parametrize("isolated", [False, True])
def test_exception_names_type_message_and_line(tmp_path, isolated):
    stderr, error, _ = failed_run(tmp_path, "raise", isolated)
    for text in (stderr, error):
        assert "py_misbehaving" in text
        assert "compute raised ValueError: fixture: this pair is not to my taste" in text
        assert re.search(FIXTURE + r":\d+ in compute\)", text), text


def test_exception_in_init_refuses_the_run(tmp_path):
    # create fails before the run starts: refused like any plugin's create, nothing written.
    out = tmp_path / "out"
    r = binocle("run", SIM_RIG, "--frames", "1", "--out", str(out), "--set", misbehaving("raise_in_init"))
    assert r.returncode == 1, r.stderr
    assert "create failed" in r.stderr
    assert "__init__ raised RuntimeError: fixture: refusing to be made" in r.stderr
    assert re.search(FIXTURE + r":\d+ in __init__\)", r.stderr), r.stderr
    assert not out.exists()


@pytest.mark.parametrize("behaviour, said", [
    ("wrong_shape", "compute returned a numpy array of dtype float32, shape (240, 321); expected a numpy array of "
                    "shape (240, 320)"),
    ("wrong_dtype", "compute returned a numpy array of dtype float64, shape (240, 320); expected"),
    ("not_an_array", "compute returned a NoneType; expected a numpy array"),
    ("nan", "compute returned 38400 of 76800 disparities not finite (NaN or infinite)"),
])
def test_wrong_results_are_refused(tmp_path, behaviour, said):
    stderr, error, _ = failed_run(tmp_path, behaviour)
    assert said in error
    assert "py_misbehaving" in error and FIXTURE in error
    assert said in stderr


def test_hang_is_killed_at_the_call_timeout(tmp_path):
    stderr, error, seconds = failed_run(tmp_path, "hang", True, "call_timeout_ms: 3000")
    assert "compute did not return within 3000 ms (call_timeout_ms)" in error, error
    assert seconds < 60


def test_crash_is_contained(tmp_path):
    stderr, error, _ = failed_run(tmp_path, "crash", True)
    assert "compute crashed in its helper process" in error and "SIGABRT" in error, error


def test_crash_restarts_as_configured(tmp_path):
    # restart: true: a new helper, the frame that crashed has no disparity, the run goes on.
    out = str(tmp_path / "out")
    r = binocle("run", SIM_RIG, "--frames", "1", "--out", out, "--set",
                misbehaving("crash", True, "restart: true, max_restarts: 1"))
    assert r.returncode == 0, r.stderr
    assert "compute crashed in its helper process (killed by signal 6 (SIGABRT)); restarting its helper (1 of 1)" in r.stderr
    s = summary(out)
    assert s["status"] == "ok" and s["isolation"]["matcher"] == {"plugin": "py_misbehaving", "restarts": 1,
                                                                 "lost_calls": 1}, s


def rss_mb(pid):
    try:
        with open(f"/proc/{pid}/status") as f:
            return int(re.search(r"VmRSS:\s+(\d+)", f.read()).group(1)) / 1024
    except (OSError, AttributeError):
        return 0.0


def children(pid):
    found = []
    for entry in os.listdir("/proc"):
        try:
            with open(f"/proc/{entry}/stat") as f:
                if entry.isdigit() and int(f.read().rsplit(")", 1)[1].split()[1]) == pid:
                    found.append(int(entry))
        except OSError:
            pass
    return found


def peak_rss(tmp_path, behaviour):
    """(Binocle's peak RSS, its helper processes' peak RSS) in MB over a 6-frame run."""
    out = str(tmp_path / behaviour)
    with subprocess.Popen([CLI, "run", SIM_RIG, "--out", out, "--set", "source.frames=6", "--set",
                           misbehaving(behaviour, True)], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True) as p:
        host = helpers = 0.0
        while p.poll() is None:
            host = max(host, rss_mb(p.pid))
            helpers = max([helpers] + [rss_mb(c) for c in children(p.pid)])
            time.sleep(0.02)
        assert p.returncode == 0 and summary(out)["status"] == "ok", p.stderr.read()
    return host, helpers


def test_leak_stays_in_the_helper_process(tmp_path):
    # 6 frames x 64 MB kept by compute: the helper grows by them, Binocle does not.
    host_leak, helper_leak = peak_rss(tmp_path, "leak")
    host_zeros, helper_zeros = peak_rss(tmp_path, "zeros")
    assert helper_leak > helper_zeros + 200, (helper_leak, helper_zeros)
    assert host_leak < host_zeros + 50, (host_leak, host_zeros)


def test_settings_are_checked_before_it_runs(tmp_path):
    r = binocle("run", SIM_RIG, "--frames", "1", "--out", str(tmp_path / "out"),
                "--set", misbehaving("explode"))
    assert r.returncode == 2, r.stderr
    assert "matcher.behaviour: value 'explode' is not valid: expected one of zeros, fixed_point" in r.stderr
    assert not (tmp_path / "out").exists()


def test_settings_reach_the_class_with_their_types(tmp_path):
    _, error, _ = failed_run(tmp_path, "echo_settings", extra="steps: [3, -4], smooth: true, label: hello, gain: 1")
    assert ("ValueError: [('behaviour', 'echo_settings'), ('gain', 1.0), ('label', 'hello'), ('num_disparities', 16), "
            "('smooth', True), ('steps', [3, -4]), ('weights', [1.0, 2.5])]") in error, error


def test_fixed_point_result_is_read_as_pixels_times_16(tmp_path):
    # int16 80 everywhere is disparity 5: every pixel valid (zeros: none).
    ratios = {}
    for behaviour in ("fixed_point", "zeros"):
        out = str(tmp_path / behaviour)
        r = binocle("run", SIM_RIG, "--frames", "1", "--out", out, "--set", misbehaving(behaviour))
        assert r.returncode == 0, r.stderr
        with open(os.path.join(out, "frames.jsonl")) as f:
            ratios[behaviour] = json.loads(f.readline())["valid_pixel_ratio"]
    assert ratios == {"fixed_point": 1.0, "zeros": 0.0}, ratios


def test_plugins_reads_tables_without_running_modules():
    r = binocle("plugins")
    assert r.returncode == 0, r.stderr
    listing = r.stdout + r.stderr
    # The SDK's checker refuses a bad table, as a C plugin's.
    assert re.search(r"py_bad_table.*window_px.*default '4' is not odd", listing), listing
    # A module that raises on import is listed: its table is read without running it.
    assert re.search(r"py_import_error\s+matcher\s+0\.1\.0", r.stdout), r.stdout
    assert "ImportError" not in listing
    # A table that is not literals is refused, the file and line said in the refusal.
    assert re.search(r"binocle_py_dynamic_table\.so: init returned no table for host ABI 1, API 1: cannot read \S+"
                     r"binocle_py_dynamic_table\.py: PluginDefinitionError: \S+binocle_py_dynamic_table\.py:10: version "
                     r"must be a literal", r.stdout), r.stdout


def test_class_changed_at_import_fails_create(tmp_path):
    r = binocle("run", SIM_RIG, "--frames", "1", "--out", str(tmp_path / "out"), "--set",
                "matcher={plugin: py_table_changed}")
    assert r.returncode == 1, r.stderr
    assert "settings differ from the literals of its source" in r.stderr, r.stderr


def test_module_that_cannot_be_imported_fails_create(tmp_path):
    r = binocle("run", SIM_RIG, "--frames", "1", "--out", str(tmp_path / "out"), "--set",
                "matcher={plugin: py_import_error}")
    assert r.returncode == 1, r.stderr
    assert "create failed" in r.stderr and "cannot load" in r.stderr
    assert re.search(r"ImportError: fixture: a module this plugin needs is missing \(at \S+binocle_py_import_error\.py:7 "
                     r"in <module>\)", r.stderr), r.stderr


def python_plugin(folder, name, source):
    """binocle_<name>.so (a copy of the bridge, as binocle_add_python_plugin makes it) and,
    unless source is None, binocle_<name>.py in `folder`; returns the environment that
    finds them."""
    folder.mkdir(exist_ok=True)
    search = os.environ["BINOCLE_PLUGIN_PATH"]
    bridge = next(os.path.join(d, "binocle_numpy_sad.so") for d in search.split(":")
                  if os.path.exists(os.path.join(d, "binocle_numpy_sad.so")))
    shutil.copy(bridge, folder / f"binocle_{name}.so")
    if source is not None:
        (folder / f"binocle_{name}.py").write_text(source)
    return {**os.environ, "BINOCLE_PLUGIN_PATH": f"{folder}:{search}"}


SYNTAX_ERROR = """import numpy as np
class Broken:
    version = "0.1.0"
    def compute(self, left, right) return left
binocle_plugin = Broken
"""


@pytest.mark.parametrize("isolated", [False, True])
def test_module_that_does_not_parse_or_is_missing_says_why(tmp_path, isolated):
    folder = tmp_path / "plugins"
    python_plugin(folder, "py_syntax", SYNTAX_ERROR)
    env = python_plugin(folder, "py_nofile", None)
    syntax = (f"{folder}/binocle_py_syntax.so: init returned no table for host ABI 1, API 1: cannot read "
              f"{folder}/binocle_py_syntax.py: SyntaxError: ")
    missing = (f"{folder}/binocle_py_nofile.so: init returned no table for host ABI 1, API 1: cannot read "
               f"{folder}/binocle_py_nofile.py: FileNotFoundError: [Errno 2] No such file or directory")
    listing = subprocess.run([CLI, "plugins"], capture_output=True, text=True, env=env, timeout=600)
    assert syntax in listing.stdout and missing in listing.stdout, listing.stdout
    assert re.search(re.escape(syntax) + r"(invalid syntax|expected ':') \(at " + re.escape(f"{folder}/binocle_py_syntax.py") +
                     r":4:\d+\)", listing.stdout), listing.stdout
    for name, said in (("py_syntax", syntax), ("py_nofile", missing)):
        block = f"plugin: {name}" + (", isolation: process" if isolated else "")
        r = subprocess.run([CLI, "run", SIM_RIG, "--frames", "1", "--out", str(tmp_path / name), "--set",
                            "matcher={" + block + "}"], capture_output=True, text=True, env=env, timeout=600)
        assert r.returncode != 0 and said.split(": init returned")[1] in r.stderr, r.stderr


def test_last_line_without_a_newline_reaches_the_log(tmp_path):
    env = python_plugin(tmp_path / "plugins", "py_print", """import numpy as np
class Prints:
    version = "0.1.0"
    description = "prints a line, then words without a newline"
    def __init__(self, settings):
        pass
    def compute(self, left, right):
        print("a whole line")
        print("last words", end="")
        return np.zeros(left.shape[:2], np.float32)
binocle_plugin = Prints
""")
    r = subprocess.run([CLI, "run", SIM_RIG, "--frames", "1", "--out", str(tmp_path / "out"), "--set",
                        "matcher={plugin: py_print, isolation: process}"], capture_output=True, text=True, env=env,
                       timeout=600)
    assert r.returncode == 0, r.stderr
    assert "[py_print] a whole line" in r.stderr and "[py_print] last words" in r.stderr, r.stderr
