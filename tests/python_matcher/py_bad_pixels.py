# SPDX-License-Identifier: MIT
# py_bad_pixels: a test fixture, an evaluator written in Python: the `disparity`
# evaluator's bad-pixel rate over all pixels (holes counted as errors) and density in numpy, so that a test compares the arrays
# the bridge hands over with what the C evaluator reads; it also reports what it saw
# (shapes, the cloud, the disparity range) as figures a test can check.
import numpy as np


class BadPixels:
    name = "py_bad_pixels"
    kind = "evaluator"
    version = "0.1.0"
    description = "test fixture: bad-pixel rate and density against gt_disparity, in numpy"
    settings = [{"name": "threshold_px", "type": "float", "default": 2.0, "min": 0, "unit": "px",
                 "help": "a matched pixel whose error exceeds this is bad"}]

    def __init__(self, settings):
        self.threshold = settings["threshold_px"]
        self.frames = 0

    def evaluate(self, frame):
        self.frames += 1
        figures = {"left_height_px": (frame.left.shape[0], "px"), "left_width_px": (frame.left.shape[1], "px"),
                   "cloud_points": 0 if frame.cloud is None else frame.cloud.shape[0]}
        if frame.disparity_range is not None:
            figures["num_disparities"] = frame.disparity_range[1]
        truth = frame.extras.get("gt_disparity")
        if truth is None or frame.disparity is None:
            return figures
        known = (truth > 0) & np.isfinite(truth)
        if "gt_valid" in frame.extras:
            known &= frame.extras["gt_valid"] != 0
        matched = known & (frame.disparity > 0) & np.isfinite(frame.disparity)
        # Holes count as errors, as the C evaluator's bad_<t>px_all_percent counts them.
        bad = (matched & (np.abs(frame.disparity - truth) > self.threshold)) | (known & ~matched)
        figures["bad_percent"] = (100.0 * bad.sum() / max(known.sum(), 1), "%")
        figures["density_percent"] = (100.0 * matched.sum() / max(known.sum(), 1), "%")
        return figures

    def finish(self):
        return {"frames_seen": self.frames}


binocle_plugin = BadPixels
