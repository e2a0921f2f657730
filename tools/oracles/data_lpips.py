"""LPIPS (AlexNet) oracle fixture from the `lpips` package, with random weights.

The weights are not stored: both this script and the Rust test generate them with SplitMix64
(tools/oracles/data_splitmix.py), so the fixture stays a few tens of kB while covering every
one of AlexNet's 2.5 M parameters. Parameter k of `model.named_parameters()` (in the order
listed in `keys`) uses seed 1000 + k; convolution weights are uniform in ±sqrt(6 / fan_in), biases in ±0.1, and the
linear layers' weights in [0, 1).

Writes crates/mannequin-data/tests/fixtures/lpips_alex.npz: the image pairs (uint8), the state
dict's keys and shapes, and lpips.LPIPS(net='alex', pretrained=False, pnet_rand=True)'s
distance (normalize=True, inputs in [0, 1]) per layer and in total.

Run: $HOME/.cache/mannequin-oracles/bin/python tools/oracles/data_lpips.py
"""

from pathlib import Path

import lpips
import numpy as np
import torch

from data_splitmix import uniform

OUT = Path(__file__).resolve().parents[2] / "crates/mannequin-data/tests/fixtures/lpips_alex.npz"


def random_weights(keys_shapes):
    out = {}
    for k, (key, shape) in enumerate(keys_shapes):
        u = uniform(1000 + k, int(np.prod(shape)))
        if key.startswith("lin"):
            v = u
        elif key.endswith(".bias"):
            v = (2 * u - 1) * 0.1
        else:
            fan_in = int(np.prod(shape[1:]))
            v = (2 * u - 1) * np.sqrt(6.0 / fan_in)
        out[key] = v.astype(np.float32).reshape(shape)
    return out


def main():
    torch.set_num_threads(2)
    model = lpips.LPIPS(net="alex", pretrained=False, pnet_rand=True, verbose=False)
    # named_parameters() lists each tensor once (`lins.i` aliases `lin{i}`); buffers are skipped.
    params = dict(model.named_parameters())
    keys_shapes = [(k, tuple(v.shape)) for k, v in params.items()]
    weights = random_weights(keys_shapes)
    with torch.no_grad():
        for k, v in weights.items():
            params[k].copy_(torch.from_numpy(v))
    model.eval()

    rng = np.random.default_rng(7)
    pairs = []
    for h, w in [(64, 64), (72, 96)]:
        y, x = np.mgrid[0:h, 0:w] / 32.0
        a = np.stack([np.sin(3 * x) * 0.4 + 0.5, np.cos(2 * y + x) * 0.4 + 0.5, (x * y) % 1.0], -1)
        a = np.clip(a + 0.1 * rng.standard_normal((h, w, 3)), 0, 1)
        b = np.clip(a + 0.15 * rng.standard_normal((h, w, 3)), 0, 1)
        pairs.append(((a * 255).round().astype(np.uint8), (b * 255).round().astype(np.uint8)))

    arrays = {}
    for i, (a, b) in enumerate(pairs):
        ta = torch.from_numpy(a.astype(np.float32) / 255).permute(2, 0, 1)[None]
        tb = torch.from_numpy(b.astype(np.float32) / 255).permute(2, 0, 1)[None]
        with torch.no_grad():
            total, layers = model(ta, tb, retPerLayer=True, normalize=True)
        arrays[f"a{i}"] = a
        arrays[f"b{i}"] = b
        arrays[f"total{i}"] = np.array(float(total.flatten()[0]))
        arrays[f"layers{i}"] = np.array([float(l.flatten()[0]) for l in layers])
        print(i, a.shape, float(total.flatten()[0]), arrays[f"layers{i}"])
    arrays["keys"] = np.array([k for k, _ in keys_shapes])
    arrays["shapes"] = np.array([list(s) + [1] * (4 - len(s)) for _, s in keys_shapes], np.int64)
    arrays["ranks"] = np.array([len(s) for _, s in keys_shapes], np.int64)
    np.savez_compressed(OUT, **arrays)
    print(OUT)


if __name__ == "__main__":
    main()
