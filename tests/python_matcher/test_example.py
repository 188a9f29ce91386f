# SPDX-License-Identifier: MIT
# The example Python matcher (examples/python_matcher): listed with its version, run on
# the aloe pair through `binocle run` with a plausible disparity against the ground
# truth, and through `binocle experiment` beside sgbm.
import json
import os
import re

from common import EXAMPLE, binocle, summary

RIG = os.path.join(EXAMPLE, "rig-aloe.yaml")


def figures(out):
    """The disparity evaluator's figures of a run (summary.json)."""
    return summary(out)["metrics"]["disparity"]


def test_plugins_lists_it_with_its_version():
    r = binocle("plugins", "--verbose")
    assert r.returncode == 0, r.stderr
    assert re.search(r"numpy_sad\s.*1\.0\.0", r.stdout), r.stdout
    assert "window_px" in r.stdout and "uniqueness_percent" in r.stdout


def test_run_on_aloe_gives_a_plausible_disparity(tmp_path):
    out = str(tmp_path / "aloe")
    r = binocle("run", RIG, "--out", out)
    assert r.returncode == 0, r.stderr
    s = summary(out)
    assert s["status"] == "ok", s
    f = figures(out)
    # Loaded machine, 2 cores: about 20 s for the 1282 x 1110 pair and 256 disparities.
    # sgbm (block 5) scores bad-2 about 10 % here; a plain SAD with a uniqueness check
    # must stay below 20 % of the pixels it matched, and match most of them. The evaluator
    # counts holes as errors (bad_2px_all_percent); the matched pixels' own rate is
    # (bad - invalid) / density.
    matched_bad = 100 * (f["bad_2px_all_percent"] - f["invalid_all_percent"]) / f["density_percent"]
    assert matched_bad < 20, f
    assert f["density_percent"] > 50, f
    assert os.path.exists(os.path.join(out, "disparity_000000.png"))


def test_settings_are_checked_with_the_sdk_rules(tmp_path):
    r = binocle("run", RIG, "--out", str(tmp_path / "x"), "--set", "matcher.window_px=4")
    assert r.returncode == 2
    assert "window_px" in r.stderr and "odd" in r.stderr, r.stderr


def test_experiment_compares_with_sgbm(tmp_path):
    out = str(tmp_path / "e1")
    experiment = os.path.join(EXAMPLE, "experiment-e1.yaml")
    r = binocle("experiment", experiment, "--out", out, "--tests", "14_numpy_sad,14_sgbm")
    assert r.returncode == 0, r.stderr
    with open(os.path.join(out, "results.json")) as f:
        tests = {t["test"]: t for t in json.load(f)["tests"]}
    assert set(tests) == {"14_numpy_sad", "14_sgbm"}, tests.keys()
    for t in tests.values():
        assert t["status"] == "ok", t
        # The paper evaluator registered the panel with either matcher.
        assert t["paper.registered"] == 1, t
