# SPDX-License-Identifier: MIT
# The `disparity` evaluator scores what an independent scoring outside Binocle gives, and
# the benchmark experiments run, on pairs of ../shared/data/stereo-gt (skipped when it is
# absent). The scoring here is numpy over the files themselves: the PFM read by its
# scale's sign (byte order) only, the masks taken where they hold 255, holes (disparity
# <= 0 or not finite) counted as errors in the bad rates, as MiddEval3's evaldisp counts
# them in its "total bad". Nothing of the shared folder is copied: a MiddEval3-shaped
# scene is made of symlinks in a temporary folder.
import csv
import json
import os
import subprocess

import numpy as np
import pytest

CLI = os.environ["BINOCLE_CLI"]
SOURCE_DIR = os.environ["BINOCLE_SOURCE_DIR"]
SHARED = os.path.normpath(os.path.join(SOURCE_DIR, "..", "shared", "data", "stereo-gt"))
needs_shared = pytest.mark.skipif(not os.path.isfile(os.path.join(SHARED, "manifest.json")),
                                  reason=f"{SHARED} is not there")


def binocle(*args):
    r = subprocess.run([CLI, *args], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    return r


def read_pfm(path):
    """A greyscale PFM, top row first: the scale's sign is the byte order, its magnitude unused."""
    with open(path, "rb") as f:
        assert f.readline().strip() == b"Pf", path
        width, height = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(4 * width * height), "<f4" if scale < 0 else ">f4")
    return np.flipud(data.reshape(height, width)).astype(np.float64)


def read_png_gray8(path):
    """An 8-bit grey PNG (non-interlaced) decoded with zlib: the masks."""
    import struct
    import zlib
    with open(path, "rb") as f:
        data = f.read()
    pos, idat, width, height = 8, b"", 0, 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", body[:10])
            assert (depth, colour) == (8, 0), (path, depth, colour)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(height, width + 1)
    out = np.zeros((height, width), np.int32)
    prev = np.zeros(width, np.int32)
    for y in range(height):
        kind, line = raw[y, 0], raw[y, 1:].astype(np.int32)
        row = np.zeros(width, np.int32)
        for x in range(width):
            a = row[x - 1] if x else 0
            b, c = prev[x], prev[x - 1] if x else 0
            p = a + b - c
            pred = [0, a, b, (a + b) // 2,
                    a if abs(p - a) <= abs(p - b) and abs(p - a) <= abs(p - c) else b if abs(p - b) <= abs(p - c) else c][kind]
            row[x] = (line[x] + pred) & 255
        out[y] = row
        prev = row
    return out


def independent_scores(gt, mask_nonocc, d):
    """Middlebury's figures as MiddEval3's evaldisp computes them, holes counted as errors."""
    known = np.isfinite(gt) & (gt > 0)
    hole = ~(np.isfinite(d) & (d > 0))
    scores = {}
    for region, sel in (("all", known), ("nonocc", known & (mask_nonocc == 255))):
        n = sel.sum()
        err = np.abs(np.where(hole, 0, d) - np.where(known, gt, 0))[sel & ~hole]
        for t in (0.5, 1, 2, 4):
            scores[f"bad_{t:g}px_{region}_percent"] = 100.0 * ((err > t).sum() + (sel & hole).sum()) / n
        scores[f"avgerr_{region}_px"] = err.mean()
        scores[f"rms_{region}_px"] = np.sqrt((err ** 2).mean())
        scores[f"invalid_{region}_percent"] = 100.0 * (sel & hole).sum() / n
    scores["density_percent"] = 100.0 * (known & ~hole).sum() / known.sum()
    return scores


@needs_shared
@pytest.mark.parametrize("pair", ["mb2014q-adirondack", "mb2014q-motorcycle"])
def test_middeval3_scene_scores_as_an_independent_scoring(tmp_path, pair):
    scene = tmp_path / "trainingQ" / pair
    scene.mkdir(parents=True)
    for name, target in (("im0.png", "left.png"), ("im1.png", "right.png"), ("calib.txt", "calib.txt"),
                         ("disp0GT.pfm", "disp0GT.pfm"), ("mask0nocc.png", "mask0nocc.png")):
        os.symlink(os.path.join(SHARED, pair, target), scene / name)
    rig = tmp_path / "rig.yaml"
    rig.write_text(f"""source: {{plugin: replay, layout: middlebury, folder: {scene}}}
matcher: {{plugin: sgbm, num_disparities: 96, block_size: 5}}
evaluators: [{{plugin: disparity}}]
outputs: {{disparity_pfm: true, cloud_ply: false}}
""")
    out = tmp_path / "out"
    binocle("run", str(rig), "--out", str(out))
    with open(out / "frames.jsonl") as f:
        binocle_scores = json.loads(f.readline())["metrics"]["disparity"]
    gt = read_pfm(scene / "disp0GT.pfm")
    assert np.nanmax(np.where(np.isfinite(gt), gt, np.nan)) < gt.shape[1]  # disparities, not 255 x them
    d = read_pfm(out / "disparity_000000.pfm")
    mine = independent_scores(gt, read_png_gray8(scene / "mask0nocc.png"), d)
    for name, value in mine.items():
        assert binocle_scores[name] == pytest.approx(value, rel=1e-3, abs=1e-9), (name, binocle_scores[name], value)
    assert binocle_scores["ground_truth_pixels"] == np.isfinite(gt).sum()


@needs_shared
def test_benchmark_experiment_gives_a_row_per_scene_the_means_charts_and_report(tmp_path):
    out = tmp_path / "bench"
    scenes = ["mb2003-teddy", "mb2014q-adirondack", "kitti2012-000070"]
    binocle("experiment", os.path.join(SOURCE_DIR, "configs/experiments/benchmark-middlebury.yaml"),
            "--set", f"dataset={SHARED}", "--set", "scenes=[" + ", ".join(scenes) + "]",
            "--set", "matcher={plugin: bm, num_disparities: 160, block_size: 9}",
            "--out", str(out), "--report", "--quiet")
    with open(out / "results.csv") as f:
        rows = list(csv.DictReader(f))
    assert [r["test"] for r in rows] == scenes + ["mean"]
    assert all(r["status"] == "ok" for r in rows), rows
    with open(out / "results.json") as f:
        tests = json.load(f)["tests"]  # full precision (results.csv rounds)
    column = "disparity.bad_2px_all_percent"
    values = [t[column] for t in tests[:-1]]
    assert tests[-1]["test"] == "mean"
    assert tests[-1][column] == pytest.approx(sum(values) / len(values), rel=1e-12)
    # The teddy pair has Middlebury's masks, the KITTI pair its noc ground truth.
    assert all(r["disparity.bad_2px_nonocc_percent"] != "" for r in rows)
    for chart in ("disparity.bad_2px_nonocc_percent", "disparity.rms_nonocc_px"):
        assert (out / (chart + ".svg")).exists() or (out / (chart + ".png")).exists(), os.listdir(out)
    assert (out / "report.html").exists()


@needs_shared
def test_kitti_benchmark_gives_d1_on_a_training_tree(tmp_path):
    # A KITTI 2012 training tree of symlinks to the shared pair, made into scene folders
    # by scripts/kitti-scene-folders.sh, then the benchmark on them.
    tree, pair = tmp_path / "training", os.path.join(SHARED, "kitti2012-000070")
    for folder, target in (("image_0", "left.png"), ("image_1", "right.png"),
                           ("disp_occ", "disp_occ_000070_10.png"), ("disp_noc", "disp_noc_000070_10.png")):
        (tree / folder).mkdir(parents=True)
        os.symlink(os.path.join(pair, target), tree / folder / "000070_10.png")
    r = subprocess.run(["sh", os.path.join(SOURCE_DIR, "scripts/kitti-scene-folders.sh"), str(tree), str(tmp_path / "pairs")],
                       capture_output=True, text=True)
    assert r.returncode == 0 and "1 pairs" in r.stdout, r.stderr
    out = tmp_path / "kitti"
    binocle("experiment", os.path.join(SOURCE_DIR, "configs/experiments/benchmark-kitti.yaml"),
            "--set", f"dataset={tmp_path / 'pairs'}", "--set", "scenes=[]",
            "--set", "matcher={plugin: bm, num_disparities: 160, block_size: 9}", "--out", str(out), "--quiet")
    with open(out / "results.csv") as f:
        rows = list(csv.DictReader(f))
    assert [r["test"] for r in rows] == ["000070_10", "mean"]
    d1 = float(rows[0]["disparity.d1_all_percent"])
    assert 0 < d1 < 100
    assert rows[0]["disparity.d1_noc_percent"] != ""  # the disp_noc ground truth gives the non-occluded pixels
