# SPDX-License-Identifier: MIT
# The arguments of the module's calls: a wrong type or value is a binocle.UsageError that
# names the argument and the value, never pybind11's cast error or a silent conversion;
# numpy scalars are the Python values they hold.
import os
import pathlib

import numpy as np
import pytest

import binocle
from binocle_files import ALOE, ROOT, cli, cli_error

ENDLESS = {"matcher.plugin": "bm", "matcher.num_disparities": 64, "matcher.block_size": 15, "source.loop": True}
E1 = os.path.join(ROOT, "configs", "experiments", "e1.yaml")


@pytest.fixture(scope="module")
def rig():
    return binocle.Rig(ALOE, set=ENDLESS)


@pytest.mark.parametrize("name", ["frames", "queue_depth"])
@pytest.mark.parametrize("value, shown", [
    (2**63, "9223372036854775808"), (1.5, "1.5"), ("3", "'3'"), (True, "True"), (0, "0"), (-1, "-1"),
    (np.float64(2.0), "2.0"),
])
def test_whole_number_arguments_of_run(rig, name, value, shown):
    with pytest.raises(binocle.UsageError) as e:
        rig.run(**{name: value})
    assert str(e.value).startswith(f"{name}={shown}: expected a whole number from 1 to 2**63-1"), str(e.value)


def test_integer_numpy_scalars_are_whole_numbers(rig):
    run = rig.run(frames=np.int64(2), queue_depth=np.uint8(3))
    assert [f.index for f in run] == [0, 1]


@pytest.mark.parametrize("value", [1.5, 2**40, "5000", None])
def test_timeout_of_plugins(value):
    with pytest.raises(binocle.UsageError, match=r"^timeout_ms=.*: expected a whole number from 100 to 2147483647"):
        binocle.plugins(timeout_ms=value)


@pytest.mark.parametrize("name", ["force", "progress"])
def test_flags_are_true_or_false(rig, name):
    with pytest.raises(binocle.UsageError, match=rf"^{name}='no': expected True or False, not a str"):
        rig.run(frames=1, **{name: "no"})
    with pytest.raises(binocle.UsageError, match=rf"^{name}=1: expected True or False"):
        binocle.experiment(E1, tests=["1"], **{name: 1})


def test_bytes_paths_are_refused(tmp_path, rig, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(binocle.UsageError) as e:
        rig.run(frames=1, out=b"dir")
    assert str(e.value).startswith("out=b'dir': a bytes path; expected a path (a str or an os.PathLike)"), str(e.value)
    with pytest.raises(binocle.UsageError, match=r"^out=b'dir': a bytes path"):
        binocle.experiment(E1, tests=["1"], out=b"dir")
    with pytest.raises(binocle.UsageError, match=r"^file=b'.*opencv-aloe.yaml': a bytes path"):
        binocle.Rig(ALOE.encode())
    assert os.listdir(tmp_path) == []  # no folder named "b'dir'" (or "dir")


def test_path_objects_are_paths(tmp_path):
    rig = binocle.Rig(pathlib.Path(ALOE), set=ENDLESS)
    run = rig.run(frames=1, out=tmp_path / "out")
    assert len(list(run)) == 1
    assert (tmp_path / "out" / "summary.json").exists()
    with pytest.raises(binocle.UsageError, match=r"^out='': expected a path .*, not an empty text"):
        rig.run(frames=1, out="")


def test_lists_of_texts(rig):
    with pytest.raises(binocle.UsageError, match=r"^tests='1': expected a list of str, not a str"):
        binocle.experiment(E1, tests="1")
    with pytest.raises(binocle.UsageError, match=r"^load=\[1\]: expected a list of str, not a list holding a int"):
        binocle.plugins(load=[1])


def test_numpy_scalars_in_set_are_their_python_values():
    rig = binocle.Rig(ALOE, set={**ENDLESS, "matcher.num_disparities": np.int64(32), "source.loop": np.bool_(True),
                                 "transforms.0.inclination_deg": np.float32(2.5), "matcher.block_size": np.array(9)})
    text = rig.yaml
    assert "num_disparities: 32" in text and "inclination_deg: 2.5" in text and "block_size: 9" in text, text
    assert [f.index for f in rig.run(frames=2)] == [0, 1]


def test_a_value_that_is_not_a_setting_names_its_key():
    with pytest.raises(binocle.UsageError) as e:
        binocle.Rig(ALOE, set={"matcher.num_disparities": object()})
    assert str(e.value).startswith("set['matcher.num_disparities']=<object object at "), str(e.value)
    assert "a object is not a setting value; expected a str, int, float, bool, None" in str(e.value)
    with pytest.raises(binocle.UsageError, match=r"^set=\{1: 2\}: the key 1 is a int; expected str keys"):
        binocle.Rig(ALOE, set={1: 2})
    with pytest.raises(binocle.UsageError, match=r"^set=5: expected a dict"):
        binocle.Rig(ALOE, set=5)


def test_none_gets_the_answer_of_null_on_the_command_line():
    # One rule for a value that says nothing: set={KEY: None} is `--set KEY=null`, and gets
    # the command's answer (the settings checker's refusal, naming the key), word for word.
    status, _, err = cli("run", ALOE, "--quiet", "--frames", "1", "--set", "matcher.num_disparities=null", check=False)
    if status == 0:
        binocle.Rig(ALOE, set={"matcher.num_disparities": None})
        return
    assert status == 2, err
    with pytest.raises(binocle.UsageError) as e:
        binocle.Rig(ALOE, set={"matcher.num_disparities": None})
    assert str(e.value) == cli_error(err, "run")
    assert "matcher.num_disparities" in str(e.value)
