# SPDX-License-Identifier: MIT
# The module under threads, fork and the interpreter's exit (docs/python.md, "Threads,
# fork and exit"). Each scenario is a script run in a Python of its own, under
# `python3 -X dev` with the fault handler on and a deadline: a hang fails the test with
# every thread's stack instead of holding the suite, a crash fails it with its signal.
import os
import subprocess
import sys
import textwrap

import pytest

from binocle_files import ALOE, read_json

# How long a scenario may take before its stacks are dumped and it is ended.
DEADLINE_S = 90

PRELUDE = f"""
import faulthandler, os, sys, threading, time
faulthandler.dump_traceback_later({DEADLINE_S}, exit=True)
import binocle
ALOE = {ALOE!r}
# The aloe pair replayed in a loop: a run that only ends when it is stopped.
ENDLESS = {{"matcher.plugin": "bm", "matcher.num_disparities": 64, "matcher.block_size": 15, "source.loop": True}}
# The same with numpy_sad, the Python matcher of examples/python_matcher, in this process.
PYTHON_MATCHER = {{"matcher": "{{plugin: numpy_sad, num_disparities: 16, window_px: 5}}", "source.loop": True}}
"""


def scenario(code, *args):
    """Runs PRELUDE + code as a script (argv[1:] = args); returns (exit status, output).
    Fails on a hang, an abort, a fatal Python error or a C++ terminate."""
    p = subprocess.run([sys.executable, "-X", "dev", "-X", "faulthandler", "-c", PRELUDE + textwrap.dedent(code), *args],
                       capture_output=True, text=True, timeout=DEADLINE_S + 30)
    output = p.stdout + p.stderr
    assert "Timeout (" not in output, "the scenario hung:\n" + output
    for fatal in ("terminate called", "Fatal Python error", "Segmentation fault", "Aborted"):
        assert fatal not in output, output
    assert p.returncode >= 0, f"killed by signal {-p.returncode}:\n{output}"
    return p.returncode, output


def test_daemon_thread_iterating_when_the_interpreter_exits(tmp_path):
    status, output = scenario("""
        rig = binocle.Rig(ALOE, set=ENDLESS)
        first = threading.Event()
        def iterate():
            for _ in rig.run(out=sys.argv[1]):
                first.set()
        threading.Thread(target=iterate, daemon=True).start()
        assert first.wait(60)
        print("main thread ends")
    """, str(tmp_path / "out"))
    assert status == 0 and "main thread ends" in output, output
    summary = read_json(str(tmp_path / "out" / "summary.json"))
    assert summary["status"] == "interrupted" and summary["frame_count"] >= 1, summary
    assert not (tmp_path / "out" / ".binocle-lock").exists()


def test_run_left_open_with_a_python_matcher_when_the_interpreter_exits(tmp_path):
    status, output = scenario("""
        rig = binocle.Rig(ALOE, set=PYTHON_MATCHER)
        run = rig.run(out=sys.argv[1])
        next(run)
        print("script ends")
    """, str(tmp_path / "out"))
    assert status == 0 and "script ends" in output, output
    summary = read_json(str(tmp_path / "out" / "summary.json"))
    assert summary["status"] == "interrupted" and summary["frame_count"] >= 1, summary


def test_close_from_another_thread_ends_the_iteration():
    status, output = scenario("""
        rig = binocle.Rig(ALOE, set={**ENDLESS, "source.rate_hz": 5})
        for attempt in range(5):
            run = rig.run()
            seen, ended = [], []
            def iterate():
                for f in run:
                    seen.append(f.index)
                ended.append(True)
            t = threading.Thread(target=iterate)
            t.start()
            time.sleep(0.3 + 0.1 * attempt)
            run.close()
            t.join(30)
            assert not t.is_alive(), "the iterator was not woken by close()"
            assert ended == [True] and run.summary["status"] == "interrupted", (ended, run.summary)
            assert seen == list(range(len(seen))), seen
        print("closed 5 times")
    """)
    assert status == 0 and "closed 5 times" in output, output


def test_two_threads_iterating_one_run_share_its_frames():
    status, output = scenario("""
        rig = binocle.Rig(ALOE, set=ENDLESS)
        run = rig.run(frames=24)
        seen = {0: [], 1: []}
        def iterate(k):
            for f in run:
                seen[k].append(f.index)
        threads = [threading.Thread(target=iterate, args=(k,)) for k in (0, 1)]
        for t in threads:
            t.start()
        ticks = 0
        while any(t.is_alive() for t in threads):  # the interpreter stays responsive meanwhile
            time.sleep(0.01)
            ticks += 1
        both = sorted(seen[0] + seen[1])
        assert both == list(range(24)), both  # each frame went to one thread
        assert run.summary["status"] == "ok" and run.summary["frame_count"] == 24, run.summary
        assert ticks > 0
        print("shared", len(seen[0]), len(seen[1]))
    """)
    assert status == 0 and "shared" in output, output


def test_four_threads_start_runs_at_once_in_a_script_that_never_imported_numpy():
    status, output = scenario("""
        rig = binocle.Rig(ALOE, set=ENDLESS)
        done, start = [], threading.Barrier(4)
        def one():
            start.wait()
            for f in rig.run(frames=2):
                f.disparity.shape
            done.append(True)
        threads = [threading.Thread(target=one) for _ in range(4)]
        for t in threads:
            t.start()
        for t in threads:
            t.join(60)
        assert len(done) == 4, done
        print("four runs")
    """)
    assert status == 0 and "four runs" in output, output


def test_a_forked_child_cannot_use_the_parents_run(tmp_path):
    status, output = scenario("""
        rig = binocle.Rig(ALOE, set=ENDLESS)
        run = rig.run(queue_depth=2, out=sys.argv[1])
        next(run)
        pid = os.fork()
        if pid == 0:
            code = 3
            try:
                for _ in range(10):
                    next(run)
            except binocle.Error as e:
                print("child:", e, flush=True)
                code = 0
            # The child's own runs work: the rig's plugins are in this process too.
            frames = [f.index for f in rig.run(frames=2)]
            print("child's own run:", frames, flush=True)
            os._exit(code if frames == [0, 1] else 4)
        _, status = os.waitpid(pid, 0)
        assert os.WIFEXITED(status) and os.WEXITSTATUS(status) == 0, status
        frame = next(run)  # the parent's run went on
        run.close()
        print("parent:", frame.index, run.summary["status"])
    """, str(tmp_path / "out"))
    assert status == 0, output
    assert "child: this run was started by process" in output and "a child it forked" in output, output
    assert "child's own run: [0, 1]" in output, output
    assert "parent: " in output and "interrupted" in output, output
    assert read_json(str(tmp_path / "out" / "summary.json"))["status"] == "interrupted"


def test_experiment_in_a_daemon_thread_when_the_interpreter_exits(tmp_path):
    status, output = scenario("""
        e1 = os.path.join(os.path.dirname(ALOE), "..", "experiments", "e1.yaml")
        tests = [str(i) for i in range(1, 9)]
        threading.Thread(target=binocle.experiment, args=(e1,), kwargs={"out": sys.argv[1], "tests": tests},
                         daemon=True).start()
        while not os.path.exists(os.path.join(sys.argv[1], "results.json")):  # a first test was written
            time.sleep(0.05)
        print("main thread ends")
    """, str(tmp_path / "out"))
    assert status == 0 and "main thread ends" in output, output
    written = read_json(str(tmp_path / "out" / "results.json"))
    assert written["status"] == "interrupted" and len(written["tests"]) < 8, written
    assert not (tmp_path / "out" / ".binocle-lock").exists()
