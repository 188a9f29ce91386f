# SPDX-License-Identifier: MIT
# numpy_sad: a matcher written in Python. Sum of absolute differences over a square
# window, winner takes all, a uniqueness check and parabolic sub-pixel refinement, all in
# vectorised numpy (one pass over the image per disparity). Built into a plugin by
# binocle_add_python_plugin(numpy_sad MODULE numpy_sad.py); see README.md.
import numpy as np

NO_COST = np.int32(2**30)


def grey(image):
    """uint8 (H, W) or (H, W, 3) in RGB order -> int32 (H, W) luma."""
    if image.ndim == 2:
        return image.astype(np.int32)
    weights = np.array([77, 150, 29], dtype=np.int32)  # BT.601, out of 256
    return (image.astype(np.int32) @ weights) >> 8


def box_sum(values, half):
    """Sum over the (2 half + 1)^2 window around each pixel (zeros outside)."""
    side = 2 * half + 1
    padded = np.pad(values, ((half + 1, half), (half + 1, half)))
    integral = padded.cumsum(axis=0, dtype=np.int32).cumsum(axis=1, dtype=np.int32)
    return (integral[side:, side:] - integral[:-side, side:]) - (integral[side:, :-side] - integral[:-side, :-side])


class NumpySad:
    name = "numpy_sad"
    kind = "matcher"
    version = "1.0.0"
    description = "SAD over a square window, winner takes all, uniqueness check, sub-pixel (vectorised numpy)"
    settings = [
        {"name": "num_disparities", "type": "int", "default": 64, "min": 1, "max": 1024, "unit": "px",
         "help": "disparities searched: min_disparity .. min_disparity + num_disparities - 1"},
        {"name": "min_disparity", "type": "int", "default": 0, "min": 0, "max": 1024, "unit": "px",
         "help": "the smallest disparity searched"},
        {"name": "window_px", "type": "int", "default": 9, "min": 3, "max": 31, "odd": True, "unit": "px",
         "help": "side of the square matching window"},
        {"name": "uniqueness_percent", "type": "float", "default": 10.0, "min": 0, "max": 100, "unit": "%",
         "help": "the best cost must be this much below any other more than 1 px away, else no match"},
        {"name": "subpixel", "type": "bool", "default": True,
         "help": "refine each disparity by a parabola through the costs beside it"},
    ]

    def __init__(self, settings):
        self.min_disparity = settings["min_disparity"]
        self.num_disparities = settings["num_disparities"]
        self.half = settings["window_px"] // 2
        self.uniqueness = settings["uniqueness_percent"]
        self.subpixel = settings["subpixel"]

    def disparity_range(self):
        return (self.min_disparity, self.num_disparities)

    def compute(self, left, right):
        left, right = grey(left), grey(right)
        height, width = left.shape
        best = np.full((height, width), NO_COST, np.int32)
        second = best.copy()
        best_d = np.full((height, width), -10, np.int32)
        before = best.copy()  # cost at best_d - 1
        after = best.copy()   # cost at best_d + 1
        previous = best.copy()
        shifted = np.empty_like(right)
        for d in range(self.min_disparity, min(self.min_disparity + self.num_disparities, width)):
            shifted[:, d:] = right[:, :width - d]
            shifted[:, :d] = right[:, :1]
            cost = box_sum(np.abs(left - shifted), self.half)
            cost[:, :d] = NO_COST  # no right pixel at x - d
            better = cost < best
            far = (d - best_d) > 1
            # Second best, more than 1 px from the best: the larger of the old best and
            # this cost is a candidate when this disparity is far from the old best.
            np.minimum(second, np.where(far, np.maximum(best, cost), NO_COST), out=second)
            np.copyto(after, cost, where=(best_d == d - 1) & ~better)
            np.copyto(before, previous, where=better)
            np.copyto(after, NO_COST, where=better)
            np.copyto(best_d, d, where=better)
            np.minimum(best, cost, out=best)
            previous = cost
        disparity = best_d.astype(np.float32)
        if self.subpixel:
            b, a, c = best.astype(np.float32), before.astype(np.float32), after.astype(np.float32)
            inner = (a < NO_COST) & (c < NO_COST)
            curvature = np.where(inner, a + c - 2 * b, 0)
            ok = inner & (curvature > 0)
            disparity += np.where(ok, (a - c) / (2 * np.where(ok, curvature, 1)), 0).astype(np.float32)
        unique = second.astype(np.float64) * 100 >= best.astype(np.float64) * (100 + self.uniqueness)
        valid = (best < NO_COST) & unique & (disparity > 0)
        return np.where(valid, disparity, np.float32(-1)).astype(np.float32)


binocle_plugin = NumpySad
