# SPDX-License-Identifier: MIT
# Errors as Python exceptions with the CLI's own message; a run left early (break,
# close, Ctrl-C) stops cleanly and writes its summary.
import os
import pathlib
import signal
import threading
import time

import pytest

import binocle
from binocle_files import ALOE, cli, cli_error, read_json, read_jsonl

# The aloe pair replayed in a loop: a run that only ends when it is stopped.
ENDLESS = {"matcher.plugin": "bm", "matcher.num_disparities": 64, "matcher.block_size": 15, "source.loop": True}


def test_exceptions_are_a_hierarchy():
    assert issubclass(binocle.Error, RuntimeError)
    assert issubclass(binocle.UsageError, binocle.Error) and issubclass(binocle.UsageError, ValueError)
    assert issubclass(binocle.PluginError, binocle.Error)


def test_missing_rig_file_has_the_cli_message(tmp_path):
    missing = str(tmp_path / "no-such-rig.yaml")
    status, _, err = cli("run", missing, "--quiet", check=False)
    assert status == 1
    with pytest.raises(binocle.Error) as e:
        binocle.Rig(missing)
    assert str(e.value) == cli_error(err, "run")
    assert "no-such-rig.yaml" in str(e.value)


@pytest.mark.parametrize("key, value, words", [
    ("matcher.num_disparites", 128, ["did you mean", "num_disparities"]),  # a key mistyped
    ("matcher.num_disparities", 100, ["num_disparities", "100"]),          # not a multiple of 16
])
def test_bad_set_has_the_cli_message(key, value, words):
    status, _, err = cli("run", ALOE, "--quiet", "--set", f"{key}={value}", check=False)
    assert status == 2
    with pytest.raises(binocle.UsageError) as e:
        binocle.Rig(ALOE, set={key: value})
    assert str(e.value) == cli_error(err, "run")
    assert all(w in str(e.value) for w in words), str(e.value)
    with pytest.raises(ValueError):  # a usage mistake is a ValueError too, as a "key=value" text
        binocle.Rig(ALOE, set=[f"{key}={value}"])


def test_bad_rig_file_has_file_line_column(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text(pathlib.Path(ALOE).read_text().replace("  num_disparities: 256", "  num_disparites: 256"))
    status, _, err = cli("run", str(bad), "--quiet", check=False)
    assert status == 1
    with pytest.raises(binocle.Error) as e:
        binocle.Rig(str(bad))
    assert str(e.value) == cli_error(err, "run")
    assert str(e.value).startswith(f"{bad}:13:3: ") and "did you mean" in str(e.value), str(e.value)


def test_malformed_set_text():
    with pytest.raises(binocle.UsageError, match="expected KEY=VALUE"):
        binocle.Rig(ALOE, set=["matcher.num_disparities"])


def test_bad_frames_argument():
    rig = binocle.Rig(ALOE, set=ENDLESS)
    with pytest.raises(binocle.UsageError, match="frames=0"):
        rig.run(frames=0)


def test_break_stops_the_run_and_writes_the_summary(tmp_path):
    rig = binocle.Rig(ALOE, set=ENDLESS)
    seen = 0
    for frame in rig.run(out=str(tmp_path)):
        seen += 1
        if seen == 3:
            break
    # The iterator is gone with the loop: the run stopped, its summary is written.
    summary = read_json(str(tmp_path / "summary.json"))
    assert summary["status"] == "interrupted"
    assert summary["frame_count"] >= 3
    assert len(read_jsonl(str(tmp_path / "frames.jsonl"))) == summary["frame_count"]
    assert not os.path.exists(tmp_path / ".binocle-lock")


def test_close_and_context_manager(tmp_path):
    rig = binocle.Rig(ALOE, set=ENDLESS)
    with rig.run() as run:
        first = next(run)
        assert first.index == 0
    assert run.summary["status"] == "interrupted"
    with pytest.raises(StopIteration):
        next(run)
    run = rig.run(frames=2)
    assert [f.index for f in run] == [0, 1]
    assert run.summary["status"] == "ok" and run.summary["frame_count"] == 2


def test_keyboard_interrupt_stops_the_run_cleanly(tmp_path):
    rig = binocle.Rig(ALOE, set=ENDLESS)
    pid = os.getpid()
    # Ctrl-C a moment after the first frame (a Timer thread sends SIGINT to this process).
    timer = threading.Timer(0.3, lambda: os.kill(pid, signal.SIGINT))
    seen = 0
    started = time.monotonic()
    try:
        with pytest.raises(KeyboardInterrupt):
            for _ in rig.run(out=str(tmp_path)):
                seen += 1
                if seen == 1:
                    timer.start()
    finally:
        timer.cancel()
    assert time.monotonic() - started < 60
    summary = read_json(str(tmp_path / "summary.json"))
    assert summary["status"] == "interrupted"
    assert summary["frame_count"] >= seen >= 1


def test_keyboard_interrupt_while_waiting_for_a_frame(tmp_path):
    # A slow consumer is not needed: the signal lands while __next__ waits (a source
    # paced at 2 frames a second), and PyErr_CheckSignals raises it there.
    rig = binocle.Rig(ALOE, set={**ENDLESS, "source.rate_hz": 2})
    pid = os.getpid()
    run = rig.run(out=str(tmp_path))
    next(run)
    timer = threading.Timer(0.1, lambda: os.kill(pid, signal.SIGINT))
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        next(run)
    timer.cancel()
    assert run.summary["status"] == "interrupted"
    assert read_json(str(tmp_path / "summary.json"))["status"] == "interrupted"


def test_a_taken_output_folder_is_refused(tmp_path):
    rig = binocle.Rig(ALOE, set=ENDLESS)
    with rig.run(out=str(tmp_path)) as first:
        next(first)
        with pytest.raises(binocle.Error):
            rig.run(out=str(tmp_path))


def test_a_failed_run_raises_the_cli_message_after_its_summary(tmp_path):
    bad = tmp_path / "not-an-image.png"
    bad.write_text("not a png")
    sets = {"source.left": str(bad), "source.right": str(bad), "source.ground_truth": ""}
    status, _, err = cli("run", ALOE, "--quiet", *[f"--set={k}={v}" for k, v in sets.items()], check=False)
    assert status == 1
    run = binocle.Rig(ALOE, set=sets).run(out=str(tmp_path / "out"))
    with pytest.raises(binocle.Error) as e:
        list(run)
    assert str(e.value) == cli_error(err, "run")
    assert "cannot decode" in str(e.value)
    assert run.summary["status"] == "failed" == read_json(str(tmp_path / "out" / "summary.json"))["status"]
