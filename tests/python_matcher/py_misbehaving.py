# SPDX-License-Identifier: MIT
# py_misbehaving: a test fixture, a Python matcher that goes wrong in the way its
# `behaviour` setting names (tests/python_matcher, bench/bench_python.cpp). Its default,
# zeros, is a well-behaved matcher that finds nothing (the benchmark's "no work").
import os
import time

import numpy as np


class Misbehaving:
    name = "py_misbehaving"
    kind = "matcher"
    version = "0.1.0"
    description = "test fixture: a Python matcher that fails as its behaviour setting says"
    settings = [
        {"name": "behaviour", "type": "enum", "default": "zeros",
         "choices": ["zeros", "fixed_point", "raise", "wrong_shape", "wrong_dtype", "not_an_array", "nan", "hang",
                     "crash", "raise_in_init", "echo_settings", "leak"],
         "help": "what compute does: zeros (all invalid, one array reused), fixed_point (int16 x 16: disparity 5), raise, "
                 "wrong_shape, wrong_dtype, not_an_array, nan, hang (never returns), crash (abort), raise_in_init, "
                 "echo_settings (raises with the settings it received), leak (keeps 64 MB more each call)"},
        {"name": "num_disparities", "type": "int", "default": 16, "min": 1, "multiple_of": 16, "unit": "px",
         "help": "what disparity_range answers"},
        {"name": "weights", "type": "float_list", "default": [1.0, 2.5], "help": "a list, for echo_settings"},
        {"name": "steps", "type": "int_list", "default": [], "help": "a list, for echo_settings"},
        {"name": "smooth", "type": "bool", "default": False, "help": "a flag, for echo_settings"},
        {"name": "label", "type": "string", "default": "none", "help": "a text, for echo_settings"},
        {"name": "gain", "type": "float", "default": 0.5, "min": 0, "max": 1, "help": "a number, for echo_settings"},
    ]

    def __init__(self, settings):
        self.behaviour = settings["behaviour"]
        if self.behaviour == "raise_in_init":
            raise RuntimeError("fixture: refusing to be made")
        self.num_disparities = settings["num_disparities"]
        self.settings = settings

    def disparity_range(self):
        return (0, self.num_disparities)

    def compute(self, left, right):
        height, width = left.shape[:2]
        b = self.behaviour
        if b == "fixed_point":
            return np.full((height, width), 5 * 16, np.int16)
        if b == "raise":
            raise ValueError("fixture: this pair is not to my taste")
        if b == "wrong_shape":
            return np.zeros((height, width + 1), np.float32)
        if b == "wrong_dtype":
            return np.zeros((height, width), np.float64)
        if b == "not_an_array":
            return None
        if b == "nan":
            d = np.ones((height, width), np.float32)
            d[: height // 2] = np.nan
            return d
        if b == "hang":
            while True:
                time.sleep(1)
        if b == "crash":
            os.abort()
        if b == "leak":
            self.kept = getattr(self, "kept", []) + [np.ones(64 << 20, np.uint8)]
        if b == "echo_settings":
            raise ValueError(repr(sorted(self.settings.items())))
        # zeros: made once per size, as a matcher that reuses its buffers would.
        if getattr(self, "zeros", None) is None or self.zeros.shape != (height, width):
            self.zeros = np.zeros((height, width), np.float32)
        return self.zeros


binocle_plugin = Misbehaving
