# SPDX-License-Identifier: MIT
# An evaluator written in Python (the py_bad_pixels fixture) beside the C `disparity`
# evaluator on the aloe pair: the arrays the bridge hands over (rectified images,
# disparity, ground truth, cloud) give the very figures the C evaluator computes from
# the host's buffers, in process and isolated.
import json
import os

import pytest

from common import SOURCE_DIR, binocle, summary

RIG = os.path.join(SOURCE_DIR, "configs/rigs/opencv-aloe.yaml")


@pytest.mark.parametrize("isolation", ["none", "process"])
def test_python_evaluator_sees_what_the_c_evaluator_sees(tmp_path, isolation):
    out = str(tmp_path / "out")
    r = binocle("run", RIG, "--out", out, "--set",
                f"evaluators=[{{plugin: disparity}}, {{plugin: py_bad_pixels, isolation: {isolation}}}]")
    assert r.returncode == 0, r.stderr
    with open(os.path.join(out, "frames.jsonl")) as f:
        frame = json.loads(f.readline())
    c, py = frame["metrics"]["disparity"], frame["metrics"]["py_bad_pixels"]
    assert py["bad_percent"] == pytest.approx(c["bad_2px_all_percent"], abs=1e-9), (c, py)
    assert py["density_percent"] == pytest.approx(c["density_percent"], abs=1e-9), (c, py)
    assert (py["left_height_px"], py["left_width_px"]) == (1110, 1282)
    assert py["cloud_points"] == frame["points"]
    assert py["num_disparities"] == 256  # the matcher's search, as disparity_range answered
    assert summary(out)["metrics"]["py_bad_pixels"]["frames_seen"] == 1  # from finish()
