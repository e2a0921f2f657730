"""A small SMPL-form `.pkl` model and the same model as `.npz`, for the Rust pickle reader.

The pickle has the shapes of the released SMPL 1.0 files (Python 2, protocol 2): a dict whose
keys and array payloads are Python 2 `str` (BINSTRING opcodes, read back with
`encoding='latin1'`), NumPy arrays pickled through `numpy.core.multiarray._reconstruct`, the
joint regressors as `scipy.sparse.csc_matrix`, `shapedirs` as a chumpy `Ch`, the strings
`bs_type` / `bs_style` and the nested dict `pose_training_info`. Two departures, both noted:

- chumpy is not installed here (it does not build on current NumPy), so a stand-in class named
  `chumpy.ch.Ch` is pickled: the same global and the same state shape (a dict holding the array
  under 'x' next to chumpy's bookkeeping entries).
- SciPy now names its module `scipy.sparse._csc` where the 2015 files say `scipy.sparse.csc`;
  the reader accepts both.

The `.npz` is what NumPy and SciPy make of the pickle (`pickle.load(..., encoding='latin1')`,
`toarray()` for sparse, `.x` for Ch), so the Rust test checks the reader against them.

Run: ../shared/tools/oracle-env.sh, then
     $ORACLE_VENV/bin/python tools/oracles/body_pickle.py crates/mannequin-body/tests/fixtures
"""
import io
import os
import pickle
import struct
import sys
import types

import numpy as np
import scipy.sparse

SMPL_PARENTS = [-1, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 9, 9, 12, 13, 14, 16, 17, 18, 19, 20, 21]
V_RINGS, V_SEGMENTS, JOINTS, BETAS = 3, 4, 24, 10  # 12 vertices: posedirs stay small


class Ch:
    """Stand-in for chumpy.ch.Ch (see the module docstring)."""


chumpy = types.ModuleType("chumpy")
chumpy.ch = types.ModuleType("chumpy.ch")
chumpy.ch.Ch = Ch
Ch.__module__, Ch.__qualname__ = "chumpy.ch", "Ch"
sys.modules.update({"chumpy": chumpy, "chumpy.ch": chumpy.ch})


class Python2Pickler(pickle._Pickler):
    """Writes `bytes` as Python 2 `str` (SHORT_BINSTRING / BINSTRING), as Python 2 pickled keys
    and array payloads; Python 3 would write `_codecs.encode` calls at protocol 2."""

    dispatch = dict(pickle._Pickler.dispatch)

    def save_py2_str(self, obj):
        n = len(obj)
        if n < 256:
            self.write(pickle.SHORT_BINSTRING + bytes([n]) + obj)
        else:
            self.write(pickle.BINSTRING + struct.pack("<i", n) + obj)
        self.memoize(obj)

    dispatch[bytes] = save_py2_str


def chumpy_ch(x):
    ch = Ch()
    ch.__dict__.update({"x": x, "_dirty_vars": set(), "_itr": None, "_parents": {}, "_cache": {"r": None}})
    return ch


def model():
    rng = np.random.default_rng(17)
    rings = (np.arange(V_RINGS) + 0.5) / V_RINGS * np.pi
    segs = np.arange(V_SEGMENTS) / V_SEGMENTS * 2 * np.pi
    phi, lam = np.meshgrid(rings, segs, indexing="ij")
    v = np.stack([0.3 * np.sin(phi) * np.cos(lam), 0.9 * np.cos(phi), 0.2 * np.sin(phi) * np.sin(lam)], -1)
    v_template = v.reshape(-1, 3)
    nv = len(v_template)
    faces = []
    for r in range(V_RINGS - 1):
        for s in range(V_SEGMENTS):
            a, b = r * V_SEGMENTS + s, r * V_SEGMENTS + (s + 1) % V_SEGMENTS
            faces += [[a, a + V_SEGMENTS, b], [b, a + V_SEGMENTS, b + V_SEGMENTS]]
    reg = np.zeros((JOINTS, nv))
    for j in range(JOINTS):
        cols = rng.choice(nv, 3, replace=False)
        reg[j, cols] = rng.uniform(0.1, 1.0, 3)
    reg /= reg.sum(1, keepdims=True)
    w = rng.uniform(0.0, 1.0, (nv, JOINTS)) * (rng.uniform(size=(nv, JOINTS)) < 0.2)
    w[np.arange(nv), rng.integers(0, JOINTS, nv)] += 0.5
    w /= w.sum(1, keepdims=True)
    kintree = np.stack([np.array(SMPL_PARENTS), np.arange(JOINTS)]).astype(np.int64)
    kintree[0, 0] = 4294967295  # as in the released files
    shapedirs = np.asfortranarray(rng.normal(0, 0.01, (nv, 3, BETAS)))  # Fortran order on purpose
    return {
        b"v_template": v_template,
        b"f": np.array(faces, dtype=np.uint32),
        b"kintree_table": kintree,
        b"J_regressor": scipy.sparse.csc_matrix(reg),
        b"J_regressor_prior": scipy.sparse.csc_matrix(reg * (reg > 0.3)),
        b"J": reg @ v_template,
        b"weights": w,
        b"weights_prior": w.astype(np.float32),
        b"posedirs": rng.normal(0, 0.01, (nv, 3, 9 * (JOINTS - 1))),
        b"shapedirs": chumpy_ch(shapedirs),
        b"vert_sym_idxs": np.arange(nv)[::-1].astype(np.int64),
        b"bs_type": b"lrotmin",
        b"bs_style": b"lbs",
        b"pose_training_info": {b"nCameras": 10, b"nSubjects": 40, b"data_root": b"/ps/project"},
    }


def arrays(loaded):
    """What NumPy and SciPy make of the loaded pickle: every array-valued entry, dense."""
    out = {}
    for k, v in loaded.items():
        if isinstance(v, Ch):
            v = v.x
        if scipy.sparse.issparse(v):
            v = v.toarray()
        if isinstance(v, np.ndarray):
            out[k] = np.ascontiguousarray(v)
    return out


def main(out_dir):
    buf = io.BytesIO()
    Python2Pickler(buf, protocol=2).dump(model())
    data = buf.getvalue()
    loaded = pickle.loads(data, encoding="latin1")
    assert isinstance(loaded[b"v_template".decode()], np.ndarray)
    with open(os.path.join(out_dir, "smpl_form.pkl"), "wb") as f:
        f.write(data)
    np.savez(os.path.join(out_dir, "smpl_form.npz"), **arrays(loaded))
    print(f"smpl_form.pkl: {len(data)} bytes; keys {sorted(loaded)}")


if __name__ == "__main__":
    main(sys.argv[1])
