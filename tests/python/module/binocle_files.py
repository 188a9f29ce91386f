# SPDX-License-Identifier: MIT
# Readers of what `binocle run --out` writes, in plain numpy (no OpenCV, no Pillow here):
# 16-bit greyscale PNG (KITTI disparity), PFM, binary PLY, and the CLI itself.
import json
import os
import struct
import subprocess
import zlib

import numpy as np

ROOT = os.environ.get("BINOCLE_SOURCE_DIR", os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "..")))
CLI = os.environ.get("BINOCLE_CLI", os.path.join(ROOT, "build", "bin", "binocle"))
ALOE = os.path.join(ROOT, "configs", "rigs", "opencv-aloe.yaml")


def cli(*args, check=True):
    """Runs `binocle ARGS`; returns (exit status, stdout, stderr)."""
    p = subprocess.run([CLI, *args], capture_output=True, text=True, timeout=600)
    if check and p.returncode != 0:
        raise AssertionError(f"binocle {' '.join(args)}: exit {p.returncode}\n{p.stderr}")
    return p.returncode, p.stdout, p.stderr


def cli_error(stderr, command):
    """The message of `binocle COMMAND: error: MESSAGE (see `binocle COMMAND --help`)`."""
    line = [x for x in stderr.splitlines() if x.startswith(f"binocle {command}: error: ")][-1]
    message = line[len(f"binocle {command}: error: "):]
    suffix = f" (see `binocle {command} --help`)"
    return message[:-len(suffix)] if message.endswith(suffix) else message


def _paeth(a, b, c):
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    return a if pa <= pb and pa <= pc else b if pb <= pc else c


def read_png_gray16(path):
    """A 16-bit greyscale PNG (no interlace) as an H x W uint16 array."""
    with open(path, "rb") as f:
        data = f.read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    pos, idat, width, height = 8, b"", 0, 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, color, _, _, interlace = struct.unpack(">IIBBBBB", body)
            assert (depth, color, interlace) == (16, 0, 0), (path, depth, color, interlace)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(height, 1 + 2 * width)
    n = 2 * width
    out = np.zeros((height, n), np.int32)
    prev = [0] * n
    for y in range(height):
        f, line = raw[y, 0], raw[y, 1:].tolist()
        if f == 0:
            row = line
        elif f == 2:
            row = [(v + p) & 255 for v, p in zip(line, prev)]
        else:
            row = [0] * n
            for x in range(n):
                a = row[x - 2] if x >= 2 else 0
                if f == 1:
                    row[x] = (line[x] + a) & 255
                elif f == 3:
                    row[x] = (line[x] + (a + prev[x]) // 2) & 255
                else:
                    row[x] = (line[x] + _paeth(a, prev[x], prev[x - 2] if x >= 2 else 0)) & 255
        out[y] = row
        prev = row
    return (out[:, 0::2] * 256 + out[:, 1::2]).astype(np.uint16)


def read_pfm(path):
    """A greyscale PFM as an H x W float32 array, top row first."""
    with open(path, "rb") as f:
        assert f.readline().strip() == b"Pf", path
        width, height = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), "<f4" if scale < 0 else ">f4")
    return np.flipud(data.reshape(height, width)).astype(np.float32)


def read_ply(path):
    """A binary little-endian PLY of x y z (float) [red green blue]: (N x 3 float32, N x 3 uint8 or None, comments)."""
    with open(path, "rb") as f:
        header, props, count, comments = [], [], 0, []
        while True:
            line = f.readline().decode("ascii").strip()
            header.append(line)
            if line.startswith("element vertex"):
                count = int(line.split()[2])
            elif line.startswith("property"):
                props.append((line.split()[2], {"float": "<f4", "uchar": "u1"}[line.split()[1]]))
            elif line.startswith("comment"):
                comments.append(line[8:])
            elif line == "end_header":
                break
        assert "format binary_little_endian 1.0" in header, header
        points = np.frombuffer(f.read(), np.dtype(props), count)
    xyz = np.stack([points["x"], points["y"], points["z"]], axis=1).astype(np.float32)
    rgb = np.stack([points["red"], points["green"], points["blue"]], axis=1) if "red" in points.dtype.names else None
    return xyz, rgb, comments


def read_json(path):
    with open(path) as f:
        return json.load(f)


def read_jsonl(path):
    with open(path) as f:
        return [json.loads(line) for line in f if line.strip()]
