# SPDX-License-Identifier: MIT
# py_bad_table: a test fixture whose settings table breaks the SDK's rules (a default
# that is not odd): the host refuses it at load, as it would a C plugin's table.
import numpy as np


class BadTable:
    name = "py_bad_table"
    version = "0.1.0"
    description = "test fixture: a Python matcher with an even default for an odd setting"
    settings = [{"name": "window_px", "type": "int", "default": 4, "odd": True, "unit": "px", "help": "window"}]

    def __init__(self, settings):
        pass

    def compute(self, left, right):
        return np.zeros(left.shape[:2], np.float32)


binocle_plugin = BadTable
