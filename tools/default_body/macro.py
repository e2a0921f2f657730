"""MakeHuman's macro model: how gender, age, muscle, weight, height and proportions weight the
`targets/macrodetails` files, and the distribution of bodies the shape space is learnt from.

A macro target's file name lists the variations it belongs to (`universal-female-young-
maxmuscle-averageweight`, `height/male-old-minmuscle-maxweight-maxheight`, ...). Its weight is the
product of the weights of those variations, each a piecewise-linear function of one macro
parameter, exactly as `macro.json` lays out the "parts" (MakeHuman's MacroModifier). Race is held
at one third each (MakeHuman's default).
"""

import numpy as np

PARAMETERS = ["gender", "age", "muscle", "weight", "height", "proportions"]

# MakeHuman's age axis: 0 -> 1 year, 0.1875 -> 11 years, 0.5 -> 25 years, 1 -> 90 years.
AGE_KNOTS_VALUE = np.array([0.0, 0.1875, 0.5, 1.0])
AGE_KNOTS_YEARS = np.array([1.0, 11.0, 25.0, 90.0])


def age_value(years):
    return np.interp(years, AGE_KNOTS_YEARS, AGE_KNOTS_VALUE)


def age_years(value):
    return np.interp(value, AGE_KNOTS_VALUE, AGE_KNOTS_YEARS)


def _hat(x, left, centre, right):
    """Piecewise-linear interpolation weight of the anchor at `centre` (1 there, 0 beyond)."""
    up = (x - left) / (centre - left) if centre > left else np.ones_like(x)
    down = (right - x) / (right - centre) if right > centre else np.ones_like(x)
    w = np.where(x <= centre, up, down)
    return np.clip(w, 0.0, 1.0)


def variation_weights(p):
    """Weights of every variation name for parameter arrays `p[name]` (each shape (N,))."""
    g, a = np.clip(p["gender"], 0, 1), np.clip(p["age"], 0, 1)
    m, w = np.clip(p["muscle"], 0, 1), np.clip(p["weight"], 0, 1)
    h, r = np.clip(p["height"], 0, 1), np.clip(p["proportions"], 0, 1)
    one = np.ones_like(g)
    out = {
        "universal": one,
        "african": one / 3,
        "asian": one / 3,
        "caucasian": one / 3,
        "female": 1 - g,
        "male": g,
        "baby": _hat(a, -1.0, 0.0, 0.1875),
        "child": _hat(a, 0.0, 0.1875, 0.5),
        "young": _hat(a, 0.1875, 0.5, 1.0),
        "old": _hat(a, 0.5, 1.0, 2.0),
        "minmuscle": _hat(m, -1.0, 0.0, 0.5),
        "averagemuscle": _hat(m, 0.0, 0.5, 1.0),
        "maxmuscle": _hat(m, 0.5, 1.0, 2.0),
        "minweight": _hat(w, -1.0, 0.0, 0.5),
        "averageweight": _hat(w, 0.0, 0.5, 1.0),
        "maxweight": _hat(w, 0.5, 1.0, 2.0),
        # Height and proportions: 0.5 applies no target, each end applies its own one.
        "minheight": np.clip(1 - 2 * h, 0, 1),
        "maxheight": np.clip(2 * h - 1, 0, 1),
        "uncommonproportions": np.clip(1 - 2 * r, 0, 1),
        "idealproportions": np.clip(2 * r - 1, 0, 1),
    }
    return out


def target_variations(name):
    """The variation tokens of a macro target file name."""
    stem = name.rsplit("/", 1)[-1].removesuffix(".target.gz")
    return stem.split("-")


def weight_matrix(target_names, params):
    """(N, K) weights of K macro targets for N parameter sets."""
    vw = variation_weights(params)
    n = len(params["gender"])
    out = np.ones((n, len(target_names)))
    for k, name in enumerate(target_names):
        for token in target_variations(name):
            if token not in vw:
                raise SystemExit(f"{name}: unknown macro variation {token!r}")
            out[:, k] *= vw[token]
    return out


def average_adult(n=1):
    """MakeHuman's default human: every parameter at 0.5 (a 25-year-old, gender-neutral)."""
    return {k: np.full(n, 0.5) for k in PARAMETERS}


def sample_population(n, seed):
    """Bodies the shape space is learnt from.

    Gender is bimodal (people are mostly clearly female or male) with mean 0.5, so the mean body
    is gender-neutral. Age is mostly adult (18-40 years), with some older adults (40-75) and a
    few older teenagers (16-18). Muscle, weight and proportions are Beta distributions around MakeHuman's
    average 0.5. MakeHuman's height slider spans about 1.1 m to 2.4 m, so height is a narrow
    normal (about 7 cm of standard deviation on its own; gender and age add the rest). Its mean
    0.54 rather than 0.5 because MakeHuman's 0.5 makes adults of 1.60 m (female) and 1.69 m
    (male), a few centimetres below typical adult averages.
    """
    rng = np.random.default_rng(seed)
    gender = rng.beta(0.7, 0.7, n)
    band = rng.choice(3, size=n, p=[0.05, 0.75, 0.20])
    lo = np.array([16.0, 18.0, 40.0])[band]
    hi = np.array([18.0, 40.0, 75.0])[band]
    years = rng.uniform(lo, hi)
    return {
        "gender": gender,
        "age": age_value(years),
        "muscle": rng.beta(3, 3, n),
        "weight": rng.beta(2.5, 2.5, n),
        "height": np.clip(rng.normal(0.54, 0.055, n), 0.25, 0.8),
        "proportions": rng.beta(2, 2, n),
    }
