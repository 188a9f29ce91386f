# SPDX-License-Identifier: MIT
# binocle.plugins() against `binocle plugins`; binocle.experiment() against the files
# `binocle experiment` writes.
import os
import re
import signal
import threading

import pytest

import binocle
from binocle_files import ROOT, cli, read_json


def cli_plugins():
    """(name, kind, version) of every line of `binocle plugins`, and the refused paths."""
    _, out, _ = cli("plugins")
    listed, refused, section = set(), set(), None
    for line in out.splitlines():
        if line.startswith("plugins ("):
            section = "plugins"
        elif line.startswith("refused:"):
            section = "refused"
        elif section == "plugins" and line.startswith("  ") and line.strip() != "none":
            m = re.match(r"\s+(\S+)\s+(\S+)\s+(\S+)\s+ABI", line)
            assert m, line
            listed.add(m.groups())
        elif section == "refused" and line.startswith("  "):
            refused.add(line.strip().split(": ")[0])
    return listed, refused


def test_plugins_as_data_equal_the_cli_listing():
    listed, refused = cli_plugins()
    plugins = binocle.plugins()
    assert {(p["name"], p["kind"], p["version"]) for p in plugins} == listed
    assert {r["path"] for r in binocle.refused_plugins()} == refused
    bm = next(p for p in plugins if p["name"] == "bm")
    assert bm["abi_version"] == binocle.ABI_VERSION and os.path.isfile(bm["path"])
    nd = next(s for s in bm["settings"] if s["name"] == "num_disparities")
    assert nd["type"] == "int" and nd["multiple_of"] == 16


def test_experiment_rows_equal_results_json(tmp_path):
    e1 = os.path.join(ROOT, "configs", "experiments", "e1.yaml")
    result = binocle.experiment(e1, set={"repeats": 2}, out=str(tmp_path), tests=["1"])
    assert result["failed"] == 0 and result["out"] == str(tmp_path)
    written = read_json(str(tmp_path / "results.json"))
    assert result["tests"] == written["tests"] and result["status"] == written["status"] == "partial"
    assert len(result["tests"]) == 1
    row = result["tests"][0]
    assert row["test"] == "1" and row["status"] == "ok"
    assert "eta_3d_percent_sd" in row  # repeats: each figure with its spread
    assert os.path.isfile(tmp_path / "results.csv")


def test_experiment_errors_have_the_cli_message(tmp_path):
    e1 = os.path.join(ROOT, "configs", "experiments", "e1.yaml")
    status, _, err = cli("experiment", e1, "--check", "--set", "repeats=0", check=False)
    assert status != 0
    with pytest.raises(binocle.Error) as e:
        binocle.experiment(e1, set={"repeats": 0}, out=str(tmp_path))
    assert str(e.value) in err


def test_keyboard_interrupt_stops_an_experiment_between_tests(tmp_path):
    e1 = os.path.join(ROOT, "configs", "experiments", "e1.yaml")
    pid = os.getpid()
    timer = threading.Timer(0.5, lambda: os.kill(pid, signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            binocle.experiment(e1, out=str(tmp_path), tests=["1", "2", "3", "4", "5", "6", "7", "8"])
    finally:
        timer.cancel()
    written = read_json(str(tmp_path / "results.json"))
    assert written["status"] == "interrupted"
    assert len(written["tests"]) < 8
