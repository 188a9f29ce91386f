# SPDX-License-Identifier: MIT
# The tests of the binocle Python module run against the build tree: CTest sets
# PYTHONPATH=build/python and BINOCLE_CLI (python/CMakeLists.txt).
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
