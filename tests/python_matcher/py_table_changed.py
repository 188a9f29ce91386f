# SPDX-License-Identifier: MIT
# py_table_changed: a test fixture whose module changes the class's settings when it
# runs: the literal table the host was given no longer holds, and create says so.
import numpy as np


class Changed:
    version = "0.1.0"
    description = "test fixture: a Python matcher whose settings change at import"
    settings = [{"name": "window_px", "type": "int", "default": 5, "help": "window"}]

    def __init__(self, settings):
        pass

    def compute(self, left, right):
        return np.zeros(left.shape[:2], np.float32)


Changed.settings = Changed.settings + [{"name": "extra", "type": "bool", "default": True, "help": "added at run time"}]
binocle_plugin = Changed
