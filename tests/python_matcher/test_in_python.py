# SPDX-License-Identifier: MIT
# The bridge loaded inside a Python process (as the `binocle` Python module loads plugins
# into one): it joins the running interpreter instead of starting one, takes the GIL
# for its calls, and computes on the same numpy. Driven through the C ABI with ctypes.
import ctypes
import os

import numpy as np

PLUGIN = os.path.join(os.environ["BINOCLE_PLUGIN_PATH"].split(":")[0], "binocle_numpy_sad.so")


class Header(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32), ("abi_version", ctypes.c_uint32), ("api_version", ctypes.c_uint32),
                ("kind", ctypes.c_int32), ("name", ctypes.c_char_p), ("version", ctypes.c_char_p),
                ("description", ctypes.c_char_p)]


class Image(ctypes.Structure):
    _fields_ = [("width", ctypes.c_int32), ("height", ctypes.c_int32), ("stride_bytes", ctypes.c_int32),
                ("format", ctypes.c_int32), ("data", ctypes.c_void_p)]


CREATE = ctypes.CFUNCTYPE(ctypes.c_int32, ctypes.c_void_p, ctypes.c_int32, ctypes.c_void_p,
                          ctypes.POINTER(ctypes.c_void_p))
DESTROY = ctypes.CFUNCTYPE(None, ctypes.c_void_p)
LAST_ERROR = ctypes.CFUNCTYPE(ctypes.c_char_p, ctypes.c_void_p)
COMPUTE = ctypes.CFUNCTYPE(ctypes.c_int32, ctypes.c_void_p, ctypes.POINTER(Image), ctypes.POINTER(Image),
                           ctypes.POINTER(Image))


class MatcherApi(ctypes.Structure):
    _fields_ = [("header", Header), ("params", ctypes.c_void_p), ("param_count", ctypes.c_int32),
                ("create", CREATE), ("destroy", DESTROY), ("last_error", LAST_ERROR), ("compute", COMPUTE)]


def image(array, pixel_format):
    return Image(array.shape[1], array.shape[0], array.strides[0], pixel_format, array.ctypes.data)


def test_bridge_joins_the_running_interpreter():
    library = ctypes.CDLL(PLUGIN)  # CDLL: the GIL is released during each call, as in a real host
    init = library.binocle_plugin_init
    init.restype = ctypes.POINTER(MatcherApi)
    api = init(1, 1).contents
    assert api.header.name == b"numpy_sad" and api.header.version == b"1.0.0"
    assert api.param_count == 5
    handle = ctypes.c_void_p()
    assert api.create(None, 0, None, ctypes.byref(handle)) == 0, api.last_error(None)
    rng = np.random.default_rng(3)
    base = rng.integers(0, 256, (120, 200), dtype=np.uint8)
    left, right = np.ascontiguousarray(base[:, :160]), np.ascontiguousarray(base[:, 8:168])
    disparity = np.zeros((120, 160), np.float32)
    rc = api.compute(handle, image(left, 1), image(right, 1), image(disparity, 5))
    assert rc == 0, api.last_error(handle)
    # The shifted copy: disparity 8 where the window fits and the match exists.
    inner = disparity[10:-10, 20:-10]
    assert abs(np.median(inner) - 8) < 0.05 and (np.abs(inner - 8) < 0.5).mean() > 0.9, inner
    # Colour: a BGR8 pair reaches Python in RGB order, so it matches as the same pair in RGB8.
    colour = rng.integers(0, 256, (120, 200, 3), dtype=np.uint8)
    rgb_l, rgb_r = np.ascontiguousarray(colour[:, :160]), np.ascontiguousarray(colour[:, 8:168])
    by_format = {}
    for fmt, (l, r) in {3: (rgb_l[..., ::-1], rgb_r[..., ::-1]), 4: (rgb_l, rgb_r)}.items():
        l, r = np.ascontiguousarray(l), np.ascontiguousarray(r)
        d = np.zeros((120, 160), np.float32)
        assert api.compute(handle, image(l, fmt), image(r, fmt), image(d, 5)) == 0, api.last_error(handle)
        by_format[fmt] = d
    assert np.array_equal(by_format[3], by_format[4])
    assert abs(np.median(by_format[4][10:-10, 20:-10]) - 8) < 0.05
    api.destroy(handle)
    # The module the bridge imported is this interpreter's: same sys.modules.
    import sys
    assert "binocle_numpy_sad" in sys.modules and "_binocle_bridge" in sys.modules
