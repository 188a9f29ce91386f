# SPDX-License-Identifier: MIT
# py_import_error: a test fixture whose module raises while it is imported. Its table is
# read from the source without running it (binocle plugins lists it); making an
# instance imports the module, and that fails with the Python error.
import numpy as np

raise ImportError("fixture: a module this plugin needs is missing")


class ImportFails:
    version = "0.1.0"
    description = "test fixture: a Python matcher whose module cannot be imported"

    def __init__(self, settings):
        pass

    def compute(self, left, right):
        return np.zeros(left.shape[:2], np.float32)


binocle_plugin = ImportFails
