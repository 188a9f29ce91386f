# SPDX-License-Identifier: MIT
# Rig.run() against `binocle run`'s output files for the same rig and the same --set:
# the disparity (16-bit KITTI PNG and PFM), the PLY cloud, frames.jsonl and summary.json.
import os

import numpy as np
import pytest

import binocle
from binocle_files import ALOE, cli, read_json, read_jsonl, read_pfm, read_ply, read_png_gray16

# bm and 128 disparities: the aloe pair at full size (1282 x 1110) in well under a second.
SET = {"matcher.plugin": "bm", "matcher.num_disparities": 128, "matcher.block_size": 15,
       "outputs.disparity_pfm": True}


def set_args(values):
    out = []
    for k, v in values.items():
        out += ["--set", f"{k}={str(v).lower() if isinstance(v, bool) else v}"]
    return out


@pytest.fixture(scope="module")
def cli_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("cli")
    cli("run", ALOE, "--frames", "1", "--quiet", "--out", str(out), *set_args(SET))
    return out


@pytest.fixture(scope="module")
def py_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("py")
    rig = binocle.Rig(ALOE, set=SET)
    run = rig.run(frames=1, out=str(out))
    frames = list(run)
    return rig, run, frames, out


def test_rig_loaded_with_overrides(py_run):
    rig, _, _, _ = py_run
    assert rig.name == "opencv-aloe"
    assert rig.matcher == "bm" and rig.source == "replay"
    assert "num_disparities: 128" in rig.yaml
    assert os.path.isabs(rig.file)


def test_arrays_shapes_and_dtypes(py_run):
    _, _, frames, _ = py_run
    assert len(frames) == 1
    f = frames[0]
    assert f.index == 0
    assert f.disparity.dtype == np.float32 and f.disparity.shape == (1110, 1282)
    assert f.left.dtype == np.uint8 and f.left.shape[:2] == (1110, 1282)
    assert f.right.shape == f.left.shape
    assert f.cloud.dtype == np.float32 and f.cloud.ndim == 2 and f.cloud.shape[1] == 3 and f.cloud.shape[0] > 1000
    assert f.colors.dtype == np.uint8 and f.colors.shape == f.cloud.shape
    assert f.cloud_frame == "ground"
    assert 0 < f.valid_pixel_ratio <= 1


def test_disparity_equals_cli_png_and_pfm(py_run, cli_run):
    _, _, frames, _ = py_run
    d = frames[0].disparity
    pfm = read_pfm(str(cli_run / "disparity_000000.pfm"))  # invalid: inf (Middlebury)
    valid = d > 0
    np.testing.assert_array_equal(np.isinf(pfm), ~valid)
    np.testing.assert_array_equal(d[valid], pfm[valid])
    png = read_png_gray16(str(cli_run / "disparity_000000.png"))
    kitti = np.where(np.isfinite(d) & (d > 0), np.minimum(np.round(d * 256), 65535), 0).astype(np.uint16)
    np.testing.assert_array_equal(png, kitti)


def test_cloud_equals_cli_ply(py_run, cli_run):
    _, _, frames, _ = py_run
    xyz, rgb, comments = read_ply(str(cli_run / "cloud_000000.ply"))
    assert any("ground" in c for c in comments), comments
    np.testing.assert_array_equal(frames[0].cloud, xyz)
    np.testing.assert_array_equal(frames[0].colors, rgb)


def test_figures_equal_cli_frames_and_summary(py_run, cli_run):
    _, run, frames, out = py_run
    line = read_jsonl(str(cli_run / "frames.jsonl"))[0]
    flat = {f"{e}.{k}": v for e, m in line["metrics"].items() for k, v in m.items() if isinstance(v, (int, float))}
    assert flat, line
    assert set(frames[0].figures) == set(flat)
    for k, v in flat.items():
        assert frames[0].figures[k] == pytest.approx(v, rel=1e-12), k
    assert frames[0].metrics == line["metrics"]
    summary, cli_summary = run.summary, read_json(str(cli_run / "summary.json"))
    assert summary["status"] == "ok" and summary["frame_count"] == 1
    assert summary["metrics"] == cli_summary["metrics"]
    # The Python run wrote the same files as `binocle run --out`.
    assert read_json(str(out / "summary.json"))["metrics"] == cli_summary["metrics"]
    np.testing.assert_array_equal(read_png_gray16(str(out / "disparity_000000.png")),
                                  read_png_gray16(str(cli_run / "disparity_000000.png")))


def test_arrays_outlive_the_run():
    rig = binocle.Rig(ALOE, set=SET)
    kept = [f.disparity for f in rig.run(frames=1)]
    del rig
    assert kept[0].shape == (1110, 1282) and np.count_nonzero(kept[0] > 0) > 1000


def test_isolated_matcher_finds_the_helper():
    # The helper process (libexec/binocle) is found from the module's own folder.
    rig = binocle.Rig(ALOE, set={**SET, "matcher.isolation": "process"})
    ref = next(iter(binocle.Rig(ALOE, set=SET).run(frames=1))).disparity
    run = rig.run(frames=1)
    frames = list(run)
    np.testing.assert_array_equal(frames[0].disparity, ref)
    assert run.summary["isolation"]["matcher"]["plugin"] == "bm"


def test_install_prefix_is_the_build_tree():
    prefix = binocle.install_prefix()
    assert os.path.isfile(os.path.join(prefix, "libexec", "binocle", "binocle-plugin-helper"))
    assert os.path.join(prefix, "lib", "binocle", "plugins") in binocle.plugin_search_path()


def test_python_matcher_in_this_python_process(tmp_path):
    # A matcher written in Python (examples/python_matcher), in process: the bridge joins
    # this interpreter, and the pipeline's thread takes the GIL the loop released while
    # waiting (a loop holding it would deadlock here).
    if "numpy_sad" not in [p["name"] for p in binocle.plugins()]:
        pytest.skip("the example Python matcher is not built (BINOCLE_PYTHON_PLUGINS=OFF)")
    here = os.path.dirname(os.path.abspath(__file__))
    repo = os.path.normpath(os.path.join(here, "..", "..", ".."))
    data = "/usr/share/doc/opencv-doc/examples/data"
    rig = tmp_path / "rig.yaml"
    rig.write_text(f"""
source: {{plugin: replay, layout: glob, left: {data}/aloeL.jpg, right: {data}/aloeR.jpg,
          ground_truth: {data}/aloeGT.png}}
calibration: {repo}/configs/calibrations/opencv-aloe-ideal.yml
matcher: {{plugin: numpy_sad, num_disparities: 64, window_px: 9}}
evaluators: [{{plugin: disparity}}]
""")
    frames = list(binocle.Rig(str(rig)).run(frames=1))
    assert len(frames) == 1
    d = frames[0].disparity
    assert d.shape == (1110, 1282) and d.dtype == np.float32
    assert frames[0].figures["disparity.density_percent"] > 30
