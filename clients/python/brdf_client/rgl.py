"""Reader of RGL material files (.bsdf, Dupuy & Jakob 2018), NumPy, written from the format as
docs/rgl-format.md states it (after Mitsuba 3's measured.cpp, pbrt-v4's MeasuredBxDF and
rgl-epfl/brdf-loader): the tensor_file container, the piecewise-bilinear 2D warps with
marginal/conditional CDFs blended linearly between parameter slices, and the evaluation
f * cos(theta_o) = spectra(vndf^-1(u_wm)) * ndf(u_wm) / (4 sigma(u_wi)). Isotropic files only.

    m = Material("sample.bsdf")
    f = m.brdf(theta_i, phi_i, theta_o, phi_o)   # radians, arrays -> (n, channels), sr^-1
"""
import os
import struct
from typing import Any, Dict

import numpy as np

DTYPES = {1: np.uint8, 2: np.int8, 3: np.uint16, 4: np.int16, 5: np.uint32, 6: np.int32,
          7: np.uint64, 8: np.int64, 9: np.float16, 10: np.float32, 11: np.float64}


def read_tensor(path: "str | os.PathLike[str]") -> Dict[str, np.ndarray]:
    """The named arrays of a tensor_file; ValueError for another file or a truncated one."""
    raw = open(path, "rb").read()
    if raw[:12] != b"tensor_file\0":
        raise ValueError("not a tensor_file (header)")
    if raw[12:14] != bytes([1, 0]):
        raise ValueError("tensor_file version is not 1.0")
    (count,) = struct.unpack_from("<I", raw, 14)
    at, fields = 18, {}  # type: Any, Dict[str, np.ndarray]
    for _ in range(count):
        (n,) = struct.unpack_from("<H", raw, at)
        name = raw[at + 2:at + 2 + n].decode("utf8")
        at += 2 + n
        ndim, dtype, offset = struct.unpack_from("<HBQ", raw, at)
        at += 11
        shape = struct.unpack_from("<" + "Q" * ndim, raw, at)
        at += 8 * ndim
        dt = np.dtype(DTYPES[dtype]).newbyteorder("<")
        size = int(np.prod(shape)) * dt.itemsize
        if offset + size > len(raw):
            raise ValueError(f"field {name} runs past the end of the file")
        fields[name] = np.frombuffer(raw, dtype=dt, count=int(np.prod(shape)),
                                     offset=offset).reshape(shape)
    return fields


class Warp2D:
    """Values on an nx-by-ny grid over [0,1]^2 (x fastest), slices over parameters."""

    def __init__(self, data, params, normalize, build_cdf):
        self.params = [np.asarray(p, np.float32) for p in params]
        self.ny, self.nx = data.shape[-2:]
        d = np.asarray(data, np.float64).reshape(-1, self.ny, self.nx)
        self.scale = (self.nx - 1) * (self.ny - 1)
        if build_cdf:
            cond = np.concatenate([np.zeros((d.shape[0], self.ny, 1)),
                                   np.cumsum(0.5 * (d[:, :, 1:] + d[:, :, :-1]), axis=2)], axis=2)
            rows = cond[:, :, -1]
            marg = np.concatenate([np.zeros((d.shape[0], 1)),
                                   np.cumsum(0.5 * (rows[:, 1:] + rows[:, :-1]), axis=1)], axis=1)
            norm = 1.0 / marg[:, -1]
            self.cond = cond * norm[:, None, None]
            self.marg = marg * norm[:, None]
            self.data = d * norm[:, None, None]
        else:
            self.data = d / (1.0 if normalize else self.scale)
        shape = [len(p) for p in self.params]
        self.shape = shape

    def _blend(self, param):
        """Per query: list of (flat slice index, weight) over the parameter corners."""
        n = len(param[0]) if param else 1
        corners = [(np.zeros(n, np.int64), np.ones(n))]
        stride = 1
        strides: list = []
        for size in reversed(self.shape):
            strides.insert(0, stride)
            stride *= size
        for d, values in enumerate(self.params):
            if len(values) == 1:
                continue
            p = np.asarray(param[d], np.float32)
            k = np.clip(np.searchsorted(values, p, side="right") - 1, 0, len(values) - 2)
            w1 = np.clip((p - values[k]) / (values[k + 1] - values[k]), 0, 1)
            corners = [(i + k * strides[d], w * (1 - w1)) for i, w in corners] + \
                      [(i + (k + 1) * strides[d], w * w1) for i, w in corners]
        return corners

    def _at(self, table, corners, *index):
        return sum(w * table[(i,) + index] for i, w in corners)

    def eval(self, x, y, param=()):
        c = self._blend(param)
        px, py = x * (self.nx - 1), y * (self.ny - 1)
        ox = np.minimum(np.floor(px).astype(np.int64), self.nx - 2).clip(0)
        oy = np.minimum(np.floor(py).astype(np.int64), self.ny - 2).clip(0)
        wx, wy = px - ox, py - oy
        v00, v10 = self._at(self.data, c, oy, ox), self._at(self.data, c, oy, ox + 1)
        v01, v11 = self._at(self.data, c, oy + 1, ox), self._at(self.data, c, oy + 1, ox + 1)
        return ((1 - wy) * ((1 - wx) * v00 + wx * v10) + wy * ((1 - wx) * v01 + wx * v11)) \
            * self.scale

    def invert(self, x, y, param=()):
        c = self._blend(param)
        sx, sy = x * (self.nx - 1), y * (self.ny - 1)
        px = np.minimum(np.floor(sx).astype(np.int64), self.nx - 2).clip(0)
        py = np.minimum(np.floor(sy).astype(np.int64), self.ny - 2).clip(0)
        sx, sy = sx - px, sy - py
        v00, v10 = self._at(self.data, c, py, px), self._at(self.data, c, py, px + 1)
        v01, v11 = self._at(self.data, c, py + 1, px), self._at(self.data, c, py + 1, px + 1)
        c0, c1 = (1 - sy) * v00 + sy * v01, (1 - sy) * v10 + sy * v11
        sx = sx * (c0 + 0.5 * sx * (c1 - c0))
        sx += (1 - sy) * self._at(self.cond, c, py, px) + sy * self._at(self.cond, c, py + 1, px)
        r0 = self._at(self.cond, c, py, np.full_like(px, self.nx - 1))
        r1 = self._at(self.cond, c, py + 1, np.full_like(px, self.nx - 1))
        sx /= (1 - sy) * r0 + sy * r1
        sy = sy * (r0 + 0.5 * sy * (r1 - r0))
        sy += self._at(self.marg, c, py)
        return sx, sy


class Material:
    """An isotropic RGL material file, ready to evaluate (brdf)."""

    def __init__(self, path: "str | os.PathLike[str]") -> None:
        f = read_tensor(path)
        self.fields = f
        self.rgb = "rgb" in f and "spectra" not in f
        values = f["rgb"] if self.rgb else f["spectra"]
        if f["phi_i"].shape[0] > 2:
            raise ValueError("anisotropic files are not read here")
        self.channels = np.arange(3, dtype=np.float32) if self.rgb else f["wavelengths"]
        self.jacobian = bool(f["jacobian"][0])
        pi, ti = f["phi_i"], f["theta_i"]
        self.ndf = Warp2D(f["ndf"], [], False, False)
        self.sigma = Warp2D(f["sigma"], [], False, False)
        self.vndf = Warp2D(f["vndf"], [pi, ti], True, True)
        self.values = Warp2D(values, [pi, ti, self.channels], False, False)

    def brdf(self, ti: Any, pi: Any, to: Any, po: Any) -> np.ndarray:
        """f in sr^-1 (n queries x channels); angles in radians, arrays."""
        wi = np.stack([np.sin(ti) * np.cos(pi), np.sin(ti) * np.sin(pi), np.cos(ti)], -1)
        wo = np.stack([np.sin(to) * np.cos(po), np.sin(to) * np.sin(po), np.cos(to)], -1)
        m = wi + wo
        m /= np.linalg.norm(m, axis=-1, keepdims=True)
        theta_i, phi_i = np.arccos(np.clip(wi[:, 2], -1, 1)), np.arctan2(wi[:, 1], wi[:, 0])
        theta_m, phi_m = np.arccos(np.clip(m[:, 2], -1, 1)), np.arctan2(m[:, 1], m[:, 0])
        u = lambda t: np.sqrt(t * 2 / np.pi)
        v = lambda p: (p + np.pi) / (2 * np.pi)
        um_y = v(phi_m - phi_i)
        um_y -= np.floor(um_y)
        sx, sy = self.vndf.invert(u(theta_m), um_y, [phi_i, theta_i])
        scale = self.ndf.eval(u(theta_m), um_y) / (4 * self.sigma.eval(u(theta_i), v(phi_i))) \
            if self.jacobian else 1.0
        out = np.stack([self.values.eval(sx, sy, [phi_i, theta_i, np.full_like(ti, ch)])
                        for ch in self.channels], -1)
        out = out * scale[:, None] / np.cos(to)[:, None]
        out[(wi[:, 2] <= 0) | (wo[:, 2] <= 0)] = 0
        return out


