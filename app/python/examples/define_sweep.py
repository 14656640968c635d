#!/usr/bin/python3
"""define_sweep.py — sweep one #define of a grammar and lay the plants out as a contact sheet.

One cell per value, left to right, top to bottom, written as a PNG. Cells are drawn by
sylva.render (the CPU ray caster, --draw render) or, with --draw lines, as orthographic
front views of the skeletons (X right, Y up) at one common scale, one line per segment
coloured by material — pure numpy, no plotting library. The PNG writer is pure Python
(zlib + struct).

    PYTHONPATH=build-py/python /usr/bin/python3 app/python/examples/define_sweep.py \
        --grammar presets/saguaro.lsys --define ARMS --values 0 1 2 3 4 5 -o arms.png
"""
import argparse
import math
import struct
import zlib

import numpy as np

import sylva

# Material colours (sRGB 8-bit): bark, leaves, succulent skin, flowers; then cycled.
MATERIAL_RGB = np.array([[107, 68, 35], [46, 139, 58], [143, 207, 90], [216, 160, 32]], dtype=np.uint8)
BACKGROUND = (245, 243, 236)


def write_png(path, rgb):
    """Writes an (H, W, 3) uint8 array as an 8-bit RGB PNG (filter 0 on every row)."""
    rgb = np.ascontiguousarray(rgb, dtype=np.uint8)
    height, width, _ = rgb.shape
    raw = np.concatenate([np.zeros((height, 1), np.uint8), rgb.reshape(height, width * 3)], axis=1)

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw.tobytes(), 6)))
        f.write(chunk(b"IEND", b""))


def linear_to_srgb8(linear_rgb):
    """Linear RGB floats to sRGB uint8 (IEC 61966-2-1), clipping at 1."""
    c = np.clip(linear_rgb, 0.0, 1.0)
    srgb = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1 / 2.4) - 0.055)
    return (srgb * 255 + 0.5).astype(np.uint8)


def draw_lines(skeleton, width, height, lo, hi):
    """An orthographic front view (X right, Y up) of the box lo..hi (x, y), one line per segment."""
    image = np.empty((height, width, 3), np.uint8)
    image[:] = BACKGROUND
    if skeleton.segment_count == 0:
        return image
    margin = 0.06
    scale = (1 - 2 * margin) * min(width / max(hi[0] - lo[0], 1e-9), height / max(hi[1] - lo[1], 1e-9))
    centre = (np.asarray(lo) + np.asarray(hi)) / 2
    pixels = np.empty((len(skeleton.positions), 2))
    pixels[:, 0] = width / 2 + (skeleton.positions[:, 0] - centre[0]) * scale
    pixels[:, 1] = height / 2 - (skeleton.positions[:, 1] - centre[1]) * scale
    start, end = pixels[skeleton.segments[:, 0]], pixels[skeleton.segments[:, 1]]
    colour = MATERIAL_RGB[skeleton.materials[skeleton.segments[:, 1]] % len(MATERIAL_RGB)]
    # Sample every segment at (at least) one point per pixel of its length.
    samples = int(max(2, np.ceil(np.abs(end - start).max()) + 1))
    t = np.linspace(0.0, 1.0, samples)[None, :, None]
    points = np.rint(start[:, None, :] + (end - start)[:, None, :] * t).astype(np.int64)
    x, y = points[..., 0].ravel(), points[..., 1].ravel()
    c = np.repeat(colour, samples, axis=0)
    inside = (x >= 0) & (x < width) & (y >= 0) & (y < height)
    image[y[inside], x[inside]] = c[inside]
    return image


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grammar", default="presets/saguaro.lsys")
    parser.add_argument("--define", default="ARMS", help="the #define to sweep")
    parser.add_argument("--values", type=float, nargs="+", default=[0, 1, 2, 3, 4, 5])
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--steps", type=int, default=None)
    parser.add_argument("--cell", default="240x320", help="cell size WxH in pixels")
    parser.add_argument("--columns", type=int, default=0, help="cells per row (default: about square)")
    parser.add_argument("--draw", choices=["render", "lines"], default="render",
                        help="render: the CPU ray caster; lines: skeleton line drawing")
    parser.add_argument("-o", "--output", default="sweep.png")
    args = parser.parse_args(argv)

    cell_w, cell_h = (int(v) for v in args.cell.lower().split("x"))
    grammar = sylva.Grammar.from_file(args.grammar)
    if args.define not in grammar.defines:
        parser.error(f"{args.grammar} has no #define {args.define} (it has: {', '.join(grammar.defines)})")
    plants = [grammar.grow(seed=args.seed, steps=args.steps, defines={args.define: v}) for v in args.values]

    # One scale for every line drawing, so the cells compare.
    if plants and any(p.joint_count for p in plants):
        joints = np.concatenate([p.positions for p in plants if p.joint_count])
        lo, hi = joints.min(axis=0), joints.max(axis=0)
    else:
        lo, hi = np.zeros(3), np.ones(3)

    columns = args.columns or math.ceil(math.sqrt(len(plants)))
    rows = math.ceil(len(plants) / columns)
    sheet = np.empty((rows * cell_h, columns * cell_w, 3), np.uint8)
    sheet[:] = BACKGROUND
    for i, plant in enumerate(plants):
        if args.draw == "render":
            cell = linear_to_srgb8(sylva.render(plant, width=cell_w, height=cell_h)[..., :3])
        else:
            cell = draw_lines(plant, cell_w, cell_h, lo, hi)
        r, c = divmod(i, columns)
        sheet[r * cell_h:(r + 1) * cell_h, c * cell_w:(c + 1) * cell_w] = cell
        sheet[r * cell_h:(r + 1) * cell_h, c * cell_w] = 200  # cell borders
        sheet[r * cell_h, c * cell_w:(c + 1) * cell_w] = 200
    write_png(args.output, sheet)
    print(f"{args.define} = {', '.join(f'{v:g}' for v in args.values)}: {len(plants)} cells "
          f"({columns}x{rows}, {args.draw}) written to {args.output}")


if __name__ == "__main__":
    main()
