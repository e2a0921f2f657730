"""Garment labels on real photos (issue 37): each photo is captured as a two-frame clip of itself
(`mannequin capture`, which fits the body and runs `mannequin segment`), and its label map is laid
over it; the pictures go side by side into docs/images/labels_photos.jpg, with what each
segmentation decided printed below.

Run from the repository root with the oracle environment's Python (it has Pillow and numpy):
    source tools/oracle-env.sh   # or ../shared/tools/oracle-env.sh
    $ORACLE_VENV/bin/python tools/docs/label_photos.py [--bin target/release/mannequin]
"""

import argparse
import json
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image

PHOTOS = Path("crates/mannequin-fit/tests/data")
# Photo (public domain or CC0: photos/PROVENANCE.md, PROVENANCE.md), and the person to capture
# where it shows several (`capture --person`).
CHOSEN = [
    ("photos/woman_and_dog.jpg", "0"),
    ("photos/soccer.jpg", None),
    ("astronaut.png", None),
    ("photos/two_men_laughing.jpg", "0"),
    ("photos/apollo11_crew.jpg", "0"),
    ("photos/backstage_bw.jpg", "0"),
]
# Label colours by name: skin, hair, shoes, then upper and lower garments.
COLOURS = {
    "skin": (240, 190, 150),
    "hair": (90, 50, 20),
    "shoes": (40, 40, 40),
    "tshirt": (230, 60, 60),
    "shirt": (230, 130, 40),
    "long-coat": (200, 40, 160),
    "pants": (40, 90, 220),
    "short-pants": (40, 180, 220),
    "skirt": (60, 180, 80),
    "dress": (160, 60, 220),
}
HEIGHT = 360


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--bin", default="target/release/mannequin")
    parser.add_argument("--out", default="docs/images/labels_photos.jpg")
    args = parser.parse_args()
    tiles, notes = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for name, person in CHOSEN:
            frames = Path(tmp) / Path(name).stem / "frames"
            frames.mkdir(parents=True)
            ext = Path(name).suffix
            for k in range(2):
                shutil.copy(PHOTOS / name, frames / f"frame_{k:04d}{ext}")
            data = Path(tmp) / Path(name).stem / "data"
            cmd = [args.bin, "capture", "--frames", str(frames), "--out", str(data)]
            if person is not None:
                cmd += ["--person", person]
            run = subprocess.run(cmd, capture_output=True, text=True)
            if run.returncode != 0:
                notes.append(f"{name}: capture refused it: {run.stderr.strip().splitlines()[-1][-200:]}")
                continue
            legend = json.loads((data / "subject.json").read_text())["labels"]
            record = json.loads((data / "labels" / "segmentation.json").read_text())["result"]
            image = np.asarray(Image.open(data / "images" / "image_0000.png").convert("RGB")).astype(float)
            labels = np.asarray(Image.open(data / "labels" / "label_0000.png"))
            colour = np.zeros_like(image)
            for index, label in enumerate(legend):
                if label in COLOURS:
                    colour[labels == index] = COLOURS[label]
            person_pixels = (labels > 0)[..., None]
            overlay = np.where(person_pixels, 0.35 * image + 0.65 * colour, 0.6 * image)
            pair = np.concatenate([image, overlay], axis=1).astype(np.uint8)
            tile = Image.fromarray(pair)
            tile = tile.resize((round(tile.width * HEIGHT / tile.height), HEIGHT), Image.LANCZOS)
            tiles.append(tile)
            e = record["evidence"]
            notes.append(
                f"{name}: {' + '.join(legend[4:])} (colour overlap {e['colour_overlap']:.2f}, forearms "
                f"{e['forearms_covered']:.2f}, shins {e['shins_covered']:.2f}, legs joined {e['legs_joined']:.2f})"
            )
    rows, row, width = [], [], 0
    for tile in tiles:
        if width + tile.width > 2400 and row:
            rows.append(row)
            row, width = [], 0
        row.append(tile)
        width += tile.width
    if row:
        rows.append(row)
    sheet = Image.new("RGB", (max(sum(t.width for t in r) for r in rows), HEIGHT * len(rows)), "white")
    for y, r in enumerate(rows):
        x = 0
        for tile in r:
            sheet.paste(tile, (x, y * HEIGHT))
            x += tile.width
    sheet.save(args.out, quality=85)
    print("\n".join(notes))
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
