#!/usr/bin/python3
"""make_leaf_texture.py — synthesises the bundled elm leaf (presets/textures/elm_leaf.png).

    /usr/bin/python3 scripts/make_leaf_texture.py [OUTPUT]   (default presets/textures/elm_leaf.png)

An 8-bit RGBA PNG drawn as a leaf image is read (docs/materials.md "Leaf images"): upright,
the petiole at the bottom row (v = 0), the tip at the top (v = 1), seen from the front;
RGB the sRGB-encoded albedo, A the cut-out (0 outside the blade). The blade is an ovate,
doubly serrate elm leaf with an asymmetric base, a pale midrib and straight parallel
lateral veins, a little lighter toward the margin; it lies just inside the polygon of
presets/elm_in_leaf.lsys's Leaf(s) in its texture coordinates, so the cut-out adds the
teeth the polygon lacks. Needs numpy only; a pure function of its constants (running it
twice gives byte-identical files).
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_textures import mix, smoothstep, srgb_encode, to_u8, write_png  # noqa: E402

SIZE = 256


def make_elm_leaf(n):
    # Texel centres: u across (0 left, 1 right), v up (0 the bottom row: the petiole).
    u = (np.arange(n) + 0.5) / n
    v = 1 - (np.arange(n) + 0.5) / n
    U, V = np.meshgrid(u, v)
    x = U - 0.5  # across, from the midrib
    # The half width of an ovate blade, widest a third of the way up, pointed at the tip,
    # its base a little higher on the right (the elm's lopsided base).
    base = np.where(x > 0, 0.06, 0.02)
    t = np.clip((V - base) / (0.985 - base), 0, 1)
    half = 0.47 * np.sin(np.pi * t ** 0.75) ** 0.9 * (1 - 0.15 * t)
    # Doubly serrate margin: big teeth between the lateral veins, small ones on them.
    teeth = 0.035 * np.abs(np.sin(np.pi * 15 * t)) + 0.012 * np.abs(np.sin(np.pi * 45 * t))
    edge = half - teeth * np.sin(np.pi * t)
    inside = np.abs(x) - edge
    alpha = 1 - smoothstep(-0.004, 0.004, inside)
    alpha = np.where(t <= 0, 0, alpha)
    # The petiole: a short stalk on the midrib below the blade.
    stalk = (np.abs(x) < 0.012) & (V < base + 0.01)
    alpha = np.maximum(alpha, stalk.astype(float))
    # Colour (linear): a leaf green, lighter toward the margin and the tip.
    green = np.array([0.055, 0.16, 0.035])
    pale = np.array([0.11, 0.25, 0.05])
    w = np.clip(np.abs(x) / np.maximum(half, 1e-6), 0, 1)
    colour = mix(green, pale, 0.5 * w + 0.3 * t)
    # The midrib and the lateral veins (straight, running up and out at ~40 degrees).
    midrib = 1 - smoothstep(0.004, 0.01, np.abs(x))
    phase = 15 * (t - 1.1 * np.abs(x))
    lateral = (1 - smoothstep(0.05, 0.14, np.abs(phase - np.round(phase)))) * (np.abs(x) < half - 0.02)
    vein = np.array([0.2, 0.32, 0.09])
    colour = mix(colour, vein, np.maximum(midrib, 0.35 * lateral))
    colour = mix(colour, np.array([0.12, 0.1, 0.04]), stalk.astype(float))
    rgba = np.zeros((n, n, 4), np.uint8)
    rgba[..., :3] = to_u8(srgb_encode(colour))
    rgba[..., 3] = np.round(np.clip(alpha, 0, 1) * 255).astype(np.uint8)
    return rgba


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "presets", "textures", "elm_leaf.png")
    write_png(out, make_elm_leaf(SIZE))
    print(out)


if __name__ == "__main__":
    main()
