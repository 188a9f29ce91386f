# SPDX-License-Identifier: MIT
# What the Python matcher tests share: the binocle command, the repository, a run that
# returns its exit status, output and summary.
import json
import os
import subprocess

CLI = os.environ["BINOCLE_CLI"]
SOURCE_DIR = os.environ["BINOCLE_SOURCE_DIR"]
SIM_RIG = os.path.join(SOURCE_DIR, "configs/rigs/sim-e1.yaml")
EXAMPLE = os.path.join(SOURCE_DIR, "examples/python_matcher")


def binocle(*args, timeout=600):
    return subprocess.run([CLI, *args], capture_output=True, text=True, timeout=timeout)


def summary(out):
    with open(os.path.join(out, "summary.json")) as f:
        return json.load(f)


def misbehaving(behaviour, isolated=False, extra=""):
    """The --set that swaps sim-e1's matcher for the fixture, behaving as asked."""
    block = f"plugin: py_misbehaving, behaviour: {behaviour}"
    if isolated:
        block += ", isolation: process"
    if extra:
        block += ", " + extra
    return "matcher={" + block + "}"
