# SPDX-License-Identifier: MIT
# What iterating rig.run() from Python costs against `binocle run`: the same rig (the aloe
# pair at 640 x 480, grey, replayed in a loop, bm with 64 disparities, ground transform,
# no outputs), the same number of frames, alternating rounds in one run; the frame rate
# of each is the pipeline's own (summary's frames_per_second), medians over the rounds.
# The Python loop touches every frame's disparity and cloud (a copy of each frame is
# made on the pipeline's writer stage: its buffers are reused by later frames).
#
# usage: PYTHONPATH=build/python /usr/bin/python3 bench/python_overhead.py [--frames 300]
#        [--rounds 5] [--json FILE]       BINOCLE_CLI: default build/bin/binocle
import argparse
import json
import os
import statistics
import struct
import subprocess
import sys
import tempfile
import time
import zlib

import numpy as np

import binocle

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
parser = argparse.ArgumentParser()
parser.add_argument("--frames", type=int, default=300)
parser.add_argument("--rounds", type=int, default=5)
parser.add_argument("--matcher", default="bm")
parser.add_argument("--json", help="also write the figures here")
args = parser.parse_args()
cli = os.environ.get("BINOCLE_CLI", os.path.join(root, "build/bin/binocle"))
WIDTH, HEIGHT = 640, 480


def write_png_gray8(path, image):
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF)
    raw = b"".join(b"\x00" + row.tobytes() for row in image)
    ihdr = struct.pack(">IIBBBBB", image.shape[1], image.shape[0], 8, 0, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))


def resized(image, width, height):
    """Area-like downsampling by averaging the 2 x 2 neighbourhood of each sample point."""
    img = image.astype(np.float32)
    ys = (np.arange(height) + 0.5) * image.shape[0] / height - 0.5
    xs = (np.arange(width) + 0.5) * image.shape[1] / width - 0.5
    y0 = np.clip(np.floor(ys).astype(int), 0, image.shape[0] - 2)
    x0 = np.clip(np.floor(xs).astype(int), 0, image.shape[1] - 2)
    fy, fx = (ys - y0)[:, None], (xs - x0)[None, :]
    a, b = img[y0][:, x0], img[y0][:, x0 + 1]
    c, d = img[y0 + 1][:, x0], img[y0 + 1][:, x0 + 1]
    out = (a * (1 - fx) + b * fx) * (1 - fy) + (c * (1 - fx) + d * fx) * fy
    return np.clip(np.round(out), 0, 255).astype(np.uint8)


def make_rig(folder):
    # The full-size pair, grey, read through Binocle itself (replay), then resized.
    aloe = binocle.Rig(os.path.join(root, "configs/rigs/opencv-aloe.yaml"),
                       set={"source.color": "gray", "matcher.plugin": "bm", "matcher.num_disparities": 64,
                            "matcher.block_size": 15})
    frame = next(iter(aloe.run(frames=1)))
    write_png_gray8(os.path.join(folder, "left_000.png"), resized(frame.left, WIDTH, HEIGHT))
    write_png_gray8(os.path.join(folder, "right_000.png"), resized(frame.right, WIDTH, HEIGHT))
    # Middlebury's f = 3740 px at 1282 px wide, B = 160 mm; already rectified.
    f = 3740.0 * WIDTH / 1282.0
    m = f"[ {f}, 0., {(WIDTH - 1) / 2}, 0., {f}, {(HEIGHT - 1) / 2}, 0., 0., 1. ]"
    mat = lambda rows, cols, data: f"!!opencv-matrix\n   rows: {rows}\n   cols: {cols}\n   dt: d\n   data: {data}\n"
    with open(os.path.join(folder, "calibration.yml"), "w") as out:
        out.write(f"%YAML:1.0\n---\nimage_width: {WIDTH}\nimage_height: {HEIGHT}\nrectified: 1\n"
                  f"M1: {mat(3, 3, m)}D1: {mat(1, 5, '[ 0., 0., 0., 0., 0. ]')}M2: {mat(3, 3, m)}"
                  f"D2: {mat(1, 5, '[ 0., 0., 0., 0., 0. ]')}R: {mat(3, 3, '[ 1., 0., 0., 0., 1., 0., 0., 0., 1. ]')}"
                  f"T: {mat(3, 1, '[ -160., 0., 0. ]')}")
    disparities = "64\n  block_size: 15" if args.matcher == "bm" else "64\n  block_size: 5"
    rig = os.path.join(folder, "aloe-640-bm.yaml")
    with open(rig, "w") as out:
        out.write(f"name: aloe-640-{args.matcher}\nsource:\n  plugin: replay\n  layout: glob\n  left: left_*.png\n"
                  f"  right: right_*.png\n  color: gray\n  loop: true\ncalibration: calibration.yml\n"
                  f"matcher:\n  plugin: {args.matcher}\n  num_disparities: {disparities}\n"
                  "transforms:\n  - plugin: ground\n    camera_height_mm: 1500\n    inclination_deg: 10\n"
                  "outputs: {disparity_png: false, disparity_color: false, cloud_ply: false}\n")
    return rig


def cli_round(rig):
    p = subprocess.run([cli, "run", rig, "--frames", str(args.frames), "--quiet"], capture_output=True, text=True, check=True)
    return json.loads(p.stdout)["frames_per_second"]


def python_round(rig):
    r = binocle.Rig(rig)
    start = time.perf_counter()
    run = r.run(frames=args.frames)
    points = 0
    for frame in run:
        points += frame.cloud.shape[0] + int(frame.disparity[0, 0] > 0)
    wall = time.perf_counter() - start
    assert run.summary["frame_count"] == args.frames, run.summary
    return run.summary["frames_per_second"], args.frames / wall


with tempfile.TemporaryDirectory(prefix="binocle-pybench-") as folder:
    rig = make_rig(folder)
    cli_round(rig)  # warm-up: page cache, plugin files
    cli_fps, py_fps, py_wall_fps = [], [], []
    for _ in range(args.rounds):
        cli_fps.append(cli_round(rig))
        fps, wall = python_round(rig)
        py_fps.append(fps)
        py_wall_fps.append(wall)
        print(f"round: binocle run {cli_fps[-1]:.1f} fps, rig.run() {py_fps[-1]:.1f} fps "
              f"(loop wall clock {py_wall_fps[-1]:.1f} fps)", file=sys.stderr)

cli_m, py_m, wall_m = statistics.median(cli_fps), statistics.median(py_fps), statistics.median(py_wall_fps)
ratio = py_m / cli_m
print(f"{WIDTH}x{HEIGHT} aloe, {args.matcher}, {args.frames} frames x {args.rounds} rounds (medians): "
      f"binocle run {cli_m:.1f} fps, rig.run() from Python {py_m:.1f} fps (loop wall clock {wall_m:.1f} fps); "
      f"ratio {ratio:.3f}, overhead {100 * (1 - ratio):.1f} % (target <= 5 %)")
if args.json:
    with open(args.json, "w") as f:
        json.dump({"cli_fps": cli_fps, "python_fps": py_fps, "python_wall_fps": py_wall_fps, "ratio": ratio}, f, indent=2)
