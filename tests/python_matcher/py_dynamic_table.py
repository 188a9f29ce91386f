# SPDX-License-Identifier: MIT
# py_dynamic_table: a test fixture whose version is computed, not a literal: the table
# is read without running the module, so the plugin is refused, saying which line.
import numpy as np

MAJOR = 1


class Dynamic:
    version = str(MAJOR) + ".0.0"
    description = "test fixture: a Python matcher whose version is computed"

    def __init__(self, settings):
        self.fill = np.float32(-1)  # never made: the table is refused first

    def compute(self, left, right):
        return np.full(left.shape[:2], self.fill)


binocle_plugin = Dynamic
