#!/usr/bin/python3
"""make_textures.py — synthesises the bundled bark, pine bark, cactus, aloe, stone and roof-tile textures
(presets/textures/).

    /usr/bin/python3 scripts/make_textures.py [OUTPUT_DIR]      (default presets/textures)

Needs numpy only; PNG files are written here with zlib + struct. The output is a pure
function of the fixed seeds below: running it twice gives byte-identical files.

Conventions (presets/textures/README.md): column index = s (around the stem, one texture
repeat per 1/u_repeat turn), row index = t (along the stem, one repeat per
1/v_per_metre metres); heights are 1 at the outermost surface and 0 at the bottom of a
furrow; albedo is sRGB-encoded. Every field is built from integer frequencies on the
512 x 512 grid (or from explicitly periodic functions), so each texture tiles seamlessly
in both directions.
"""
import os
import struct
import sys
import zlib

import numpy as np

SIZE = 512
BARK_SEED = 20240611
CACTUS_SEED = 20240612
STONE_SEED = 20261202
TILES_SEED = 20261203
ALOE_SEED = 20261204
PINE_SEED = 20261207


# --- PNG ------------------------------------------------------------------------------

def _filter_rows(raw, bpp):
    """PNG filtering (RFC 2083 6): per row, the filter among None/Sub/Up/Average/Paeth
    with the smallest sum of absolute signed residuals (the libpng heuristic)."""
    h, stride = raw.shape
    x = raw.astype(np.int16)
    a = np.zeros_like(x)
    a[:, bpp:] = x[:, :-bpp]
    b = np.zeros_like(x)
    b[1:, :] = x[:-1, :]
    c = np.zeros_like(x)
    c[1:, bpp:] = x[:-1, :-bpp]
    p = a + b - c
    pa, pb, pc = np.abs(p - a), np.abs(p - b), np.abs(p - c)
    paeth = np.where((pa <= pb) & (pa <= pc), a, np.where(pb <= pc, b, c))
    candidates = [x, x - a, x - b, x - ((a + b) >> 1), x - paeth]
    residuals = [(cand & 0xFF).astype(np.uint8) for cand in candidates]
    cost = np.stack([np.abs(r.astype(np.int8).astype(np.int32)).sum(axis=1) for r in residuals])
    choice = np.argmin(cost, axis=0)
    out = bytearray()
    for y in range(h):
        out.append(int(choice[y]))
        out += residuals[choice[y]][y].tobytes()
    return bytes(out)


def write_png(path, pixels):
    """pixels: (h, w) uint16 (16-bit grey), (h, w, 3) uint8 (8-bit RGB) or (h, w, 4) uint8
    (8-bit RGBA, straight alpha)."""
    if pixels.ndim == 2 and pixels.dtype == np.uint16:
        bit_depth, colour_type, bpp = 16, 0, 2
        raw = pixels.astype(">u2").view(np.uint8).reshape(pixels.shape[0], -1)
    elif pixels.ndim == 3 and pixels.shape[2] == 3 and pixels.dtype == np.uint8:
        bit_depth, colour_type, bpp = 8, 2, 3
        raw = pixels.reshape(pixels.shape[0], -1)
    elif pixels.ndim == 3 and pixels.shape[2] == 4 and pixels.dtype == np.uint8:
        bit_depth, colour_type, bpp = 8, 6, 4
        raw = pixels.reshape(pixels.shape[0], -1)
    else:
        raise ValueError("unsupported pixel array")
    h, w = pixels.shape[:2]

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n"
    png += chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, bit_depth, colour_type, 0, 0, 0))
    if colour_type in (2, 6):
        png += chunk(b"sRGB", b"\x00")  # perceptual; the albedo is sRGB-encoded
    png += chunk(b"IDAT", zlib.compress(_filter_rows(raw, bpp), 9))
    png += chunk(b"IEND", b"")
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(png)
    os.replace(tmp, path)


# --- fields ---------------------------------------------------------------------------

def spectral_noise(rng, n, band, beta, stretch_t):
    """Zero-mean, unit-variance periodic noise on an n x n grid: white noise filtered in
    the Fourier domain by |k|^-beta for |k| in band (cycles per image), where
    |k| = sqrt(ks^2 + (stretch_t * kt)^2) — stretch_t > 1 elongates features along t."""
    white = rng.standard_normal((n, n))
    spectrum = np.fft.rfft2(white)
    kt = np.fft.fftfreq(n, 1.0 / n)[:, None]
    ks = np.fft.rfftfreq(n, 1.0 / n)[None, :]
    k = np.sqrt(ks ** 2 + (stretch_t * kt) ** 2)
    lo, hi = band
    gain = np.where((k >= lo) & (k <= hi), np.maximum(k, 1e-9) ** -beta, 0.0)
    field = np.fft.irfft2(spectrum * gain, s=(n, n))
    field -= field.mean()
    return field / field.std()


def warp(field, dt, ds):
    """Samples a periodic field at (row + dt, col + ds) with bilinear interpolation and
    wrap-around; periodic displacements keep the result periodic."""
    n_t, n_s = field.shape
    t = (np.arange(n_t)[:, None] + dt) % n_t
    s = (np.arange(n_s)[None, :] + ds) % n_s
    t0 = np.floor(t).astype(int)
    s0 = np.floor(s).astype(int)
    ft, fs = t - t0, s - s0
    t1, s1 = (t0 + 1) % n_t, (s0 + 1) % n_s
    return ((1 - ft) * (1 - fs) * field[t0, s0] + (1 - ft) * fs * field[t0, s1] +
            ft * (1 - fs) * field[t1, s0] + ft * fs * field[t1, s1])


def smoothstep(e0, e1, x):
    x = np.clip((x - e0) / (e1 - e0), 0.0, 1.0)
    return x * x * (3 - 2 * x)


def srgb_encode(linear):
    linear = np.clip(linear, 0.0, 1.0)
    return np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * linear ** (1 / 2.4) - 0.055)


def to_u8(srgb):
    return np.clip(np.round(srgb * 255.0), 0, 255).astype(np.uint8)


def to_u16(height):
    return np.clip(np.round(height * 65535.0), 0, 65535).astype(np.uint16)


def mix(a, b, w):
    """Per-pixel linear blend of two colours (3-vectors or fields) by weight w."""
    return a * (1 - w[..., None]) + b * w[..., None]


# --- bark -----------------------------------------------------------------------------

def furrow_distance(rng, n, count, wander, modes):
    """Distance across s (in furrow spacings, 0..0.5) to the nearest of `count` furrow
    lines; line i sits at s = (i + 0.5)/count plus a wander made of sine modes 1..modes
    along t (integer frequencies, so it is periodic), amplitude `wander` spacings."""
    t = (np.arange(n)[:, None] + 0.5) / n
    s = (np.arange(n)[None, :] + 0.5) / n
    best = np.full((n, n), np.inf)
    for i in range(count):
        centre = (i + 0.5) / count
        for k in range(1, modes + 1):
            centre = centre + wander / count * rng.uniform(0.3, 1.0) / k * np.sin(2 * np.pi * (k * t + rng.uniform()))
        offset = (s - centre) * count
        offset -= np.round(offset / count) * count      # periodic in s
        best = np.minimum(best, np.abs(offset))
    return best


def make_bark(n):
    """Furrowed bark (elm, oak, poplar): plates separated by furrows that run along the
    stem. Each furrow is a line that wanders across s with a few periodic sine modes
    along t, so neighbours approach, touch and part again (plates pinch out, furrows
    merge and split); shallower secondary furrows split the plates; the plates carry a
    convex profile, fibres along t and a few short horizontal cracks."""
    rng = np.random.default_rng(BARK_SEED)
    warp_s = spectral_noise(rng, n, (3.0, 24.0), 1.0, 2.0)
    warp_t = spectral_noise(rng, n, (3.0, 24.0), 1.0, 2.0)
    main = warp(furrow_distance(rng, n, 9, 0.55, 4), 4.0 * warp_t, 2.5 * warp_s)
    minor = warp(furrow_distance(rng, n, 17, 0.9, 5), 4.0 * warp_t, 2.5 * warp_s)
    width = 0.36 + 0.10 * spectral_noise(rng, n, (1.0, 6.0), 1.0, 3.0)   # furrow half-width, spacings
    plate = smoothstep(0.02, 1.0, main / width) ** 0.7
    plate *= 1.0 - 0.35 * (1.0 - smoothstep(0.0, 0.18, minor))
    grain = spectral_noise(rng, n, (12.0, 120.0), 0.8, 5.0)     # fibres along t
    lumps = spectral_noise(rng, n, (2.0, 10.0), 1.0, 1.5)
    cracks_noise = spectral_noise(rng, n, (4.0, 16.0), 1.0, 0.3)  # elongated across s
    cracks = (1.0 - smoothstep(0.0, 0.12, np.abs(cracks_noise))) * smoothstep(0.6, 0.95, plate)
    cracks *= smoothstep(0.5, 1.2, spectral_noise(rng, n, (2.0, 8.0), 1.0, 1.0))  # only some

    height = plate * (0.86 + 0.07 * lumps) + 0.025 * grain * plate - 0.25 * cracks
    height = (height - height.min()) / (height.max() - height.min())

    # Albedo (linear): dark, slightly reddish furrows; grey-brown plates weathered lighter
    # on their tops; faint greenish tint (algae/lichen) in patches.
    furrow = np.array([0.030, 0.021, 0.014])
    plate_dark = np.array([0.115, 0.088, 0.064])
    plate_light = np.array([0.205, 0.180, 0.150])
    lichen = np.array([0.140, 0.160, 0.095])
    tint = spectral_noise(rng, n, (2.0, 12.0), 1.2, 1.0)
    speck = spectral_noise(rng, n, (40.0, 200.0), 0.3, 2.0)
    colour = mix(furrow, plate_dark, smoothstep(0.05, 0.55, height))
    colour = mix(colour, plate_light, smoothstep(0.55, 1.0, height) * (0.6 + 0.25 * np.clip(lumps, -1.6, 1.6)))
    colour = mix(colour, lichen, 0.35 * smoothstep(0.8, 1.8, tint) * smoothstep(0.4, 0.8, height))
    colour *= (1.0 + 0.10 * grain + 0.05 * speck)[..., None]
    colour *= (1.0 - 0.6 * cracks)[..., None]
    return to_u8(srgb_encode(colour)), to_u16(height)


# --- cactus ---------------------------------------------------------------------------

AREOLES_PER_REPEAT = 4  # along t, per texture repeat


def make_cactus(n):
    """Ribbed cactus skin (saguaro): one rib per texture repeat across s with its crest
    at s = 0.5 and the groove at s = 0 (= 1), a smooth periodic profile; small raised,
    lighter areoles along the crest, AREOLES_PER_REPEAT per repeat along t; a waxy green
    skin a little darker in the grooves."""
    rng = np.random.default_rng(CACTUS_SEED)
    s = (np.arange(n)[None, :] + 0.5) / n
    t = (np.arange(n)[:, None] + 0.5) / n
    wobble = spectral_noise(rng, n, (1.0, 4.0), 1.5, 1.0)        # the crest wanders a little
    s_rib = s + 0.012 * wobble
    rib = ((1.0 - np.cos(2.0 * np.pi * s_rib)) / 2.0) ** 0.8    # 0 in the groove, 1 on the crest

    # Areoles: elliptical pads centred on the crest, every 1/AREOLES_PER_REPEAT along t.
    phase_t = (t * AREOLES_PER_REPEAT) % 1.0 - 0.5          # -0.5..0.5 between areoles
    ds = (s_rib - 0.5) / 0.030                               # in areole radii
    dt = phase_t * (1.0 / AREOLES_PER_REPEAT) / 0.036
    r2 = ds ** 2 + dt ** 2
    areole = np.exp(-r2 * 1.6) * smoothstep(1.25, 0.85, np.sqrt(r2))
    fine = spectral_noise(rng, n, (20.0, 160.0), 0.5, 1.0)
    streaks = spectral_noise(rng, n, (6.0, 60.0), 1.0, 6.0)     # faint vertical streaks

    height = 0.94 * rib + 0.04 * areole + 0.004 * fine * rib
    height = (height - height.min()) / (height.max() - height.min())

    groove = np.array([0.035, 0.070, 0.030])
    skin = np.array([0.095, 0.160, 0.068])
    crest = np.array([0.120, 0.185, 0.090])
    pad = np.array([0.50, 0.44, 0.34])
    colour = mix(groove, skin, smoothstep(0.0, 0.45, rib))
    colour = mix(colour, crest, smoothstep(0.7, 1.0, rib))
    colour *= (1.0 + 0.05 * streaks + 0.03 * fine)[..., None]
    colour = mix(colour, pad * (1.0 + 0.08 * fine)[..., None], smoothstep(0.15, 0.55, areole))
    return to_u8(srgb_encode(colour)), to_u16(height)


# --- aloe -----------------------------------------------------------------------------

ALOE_FLECKS = 90  # pale flecks per repeat


def make_aloe(n):
    """Aloe vera skin (presets/aloe_vera.lsys): a glaucous grey-green with faint streaks
    along t (the leaf's length), scattered pale whitish flecks elongated along t (as on a
    young aloe vera leaf), each a soft ellipse about 1/23 of the repeat across and 1/14
    along, of varying size and brightness, placed at random with wrap-around so the
    texture tiles. Albedo only (no height)."""
    rng = np.random.default_rng(ALOE_SEED)
    s = (np.arange(n)[None, :] + 0.5) / n
    t = (np.arange(n)[:, None] + 0.5) / n
    streaks = spectral_noise(rng, n, (4.0, 80.0), 0.9, 8.0)     # fine streaks along t
    blotch = spectral_noise(rng, n, (1.0, 6.0), 1.2, 1.0)       # broad tint
    fine = spectral_noise(rng, n, (40.0, 200.0), 0.4, 1.0)
    wobble = spectral_noise(rng, n, (6.0, 30.0), 1.0, 1.0)      # ragged fleck edges
    fleck = np.zeros((n, n))
    for _ in range(ALOE_FLECKS):
        cs, ct = rng.uniform(), rng.uniform()
        size = rng.uniform(0.6, 1.3)
        ds = s - cs
        ds -= np.round(ds)                                       # periodic
        dt = t - ct
        dt -= np.round(dt)
        r2 = (ds / (0.022 * size)) ** 2 + (dt / (0.036 * size)) ** 2
        fleck = np.maximum(fleck, rng.uniform(0.6, 1.0) * (1 - smoothstep(0.55, 1.0, r2 + 0.25 * wobble)))
    skin = np.array([0.150, 0.235, 0.140])
    glaucous = np.array([0.185, 0.265, 0.190])   # the bloom: greyer, bluer
    pale = np.array([0.50, 0.56, 0.46])
    colour = mix(skin, glaucous, smoothstep(-1.5, 1.5, blotch))
    colour *= (1.0 + 0.06 * streaks + 0.03 * fine)[..., None]
    colour = mix(colour, pale * (1.0 + 0.05 * fine)[..., None], fleck)
    return to_u8(srgb_encode(colour))


# --- the well's stone and roof tiles (Bhagvat et al. 2009 fig. 10) --------------------------------

STONE_COURSES = 8        # courses of blocks per repeat along t
STONE_BLOCKS = 6         # blocks per course across s (alternate courses offset by half)
TILE_ROWS = 16           # rows of roof tiles per repeat along t
TILE_COLUMNS = 16        # tiles per row across s


def running_bond(n, rows, columns):
    """Cells in running bond on the n x n grid: `rows` rows per repeat along t, `columns`
    cells a row across s, odd rows shifted by half a cell. Returns each texel's row and
    cell index and its fractions (fu across, ft along) within the cell."""
    s = (np.arange(n)[None, :] + 0.5) / n
    t = (np.arange(n)[:, None] + 0.5) / n
    row = np.floor(t * rows)
    u = s * columns + 0.5 * (row % 2)
    return row, np.floor(u) % columns, u % 1.0, (t * rows) % 1.0


def make_stone(n):
    """Dressed stone blocks in running bond (the well's wall): STONE_COURSES courses per
    repeat along t, STONE_BLOCKS blocks per course across s, alternate courses shifted by
    half a block; mortar joints are the grooves (height 0), each block's face bulges a
    little and carries its own tint and pitting."""
    rng = np.random.default_rng(STONE_SEED)
    course, block, fu, ft = running_bond(n, STONE_COURSES, STONE_BLOCKS)
    edge = np.minimum(np.minimum(fu, 1 - fu) * 1.6, np.minimum(ft, 1 - ft))  # to the nearest joint
    face = smoothstep(0.02, 0.09, edge)
    bulge = np.sin(np.pi * fu) * np.sin(np.pi * ft)
    pits = spectral_noise(rng, n, (24.0, 160.0), 0.6, 1.0)
    tint_of = rng.uniform(-1.0, 1.0, (STONE_COURSES, STONE_BLOCKS))
    tint = tint_of[course.astype(int) % STONE_COURSES, block.astype(int)]
    height = face * (0.75 + 0.2 * bulge + 0.03 * pits)
    height = (height - height.min()) / (height.max() - height.min())
    mortar = np.array([0.30, 0.28, 0.25])
    stone = np.array([0.42, 0.37, 0.30])
    colour = stone * (1.0 + 0.12 * tint + 0.05 * pits)[..., None]
    colour = mix(mortar, colour, face)
    return to_u8(srgb_encode(colour)), to_u16(height)


def make_tiles(n):
    """Overlapping roof tiles (the well's roof): TILE_ROWS rows per repeat along t, each
    tile rising from its lower edge (height 0, where the row above overlaps it) to 1,
    rounded across s; alternate rows offset by half a tile; terracotta with a per-tile tint."""
    rng = np.random.default_rng(TILES_SEED)
    row, tile, fu, ft = running_bond(n, TILE_ROWS, TILE_COLUMNS)
    rise = ft ** 0.7                                  # 0 at the overlapped edge, 1 at the lip
    round_across = np.sin(np.pi * fu) ** 0.5
    grain = spectral_noise(rng, n, (30.0, 160.0), 0.5, 1.0)
    tint_of = rng.uniform(-1.0, 1.0, (TILE_ROWS, TILE_COLUMNS))
    tint = tint_of[row.astype(int) % TILE_ROWS, tile.astype(int)]
    height = rise * (0.55 + 0.45 * round_across) + 0.01 * grain
    height = (height - height.min()) / (height.max() - height.min())
    clay = np.array([0.38, 0.13, 0.07])
    shade = np.array([0.16, 0.06, 0.04])
    colour = clay * (1.0 + 0.15 * tint + 0.04 * grain)[..., None]
    colour = mix(shade, colour, smoothstep(0.0, 0.35, rise))
    return to_u8(srgb_encode(colour)), to_u16(height)


# --- the upper bark of a Scots pine -----------------------------------------------------

def make_pine_bark(n):
    """The thin upper bark of a Scots pine (presets/scots_pine.lsys, material 2): a fox-red
    to orange skin peeling in papery flakes that are wider around the stem (s) than along
    it (t), paler where a flake has lifted, with a dark hairline where its edge casts a
    shadow, and a fine grain. Albedo only (no height): the scene's materials table lays it
    on the segments (u_repeat, v_per_metre; docs/materials.md)."""
    rng = np.random.default_rng(PINE_SEED)
    flakes = spectral_noise(rng, n, (2.0, 24.0), 1.4, 0.35)       # papery plates, long around
    tint = spectral_noise(rng, n, (1.0, 6.0), 1.0, 1.0)          # broad redder / browner areas
    grain = spectral_noise(rng, n, (30.0, 200.0), 0.4, 0.3)      # fine grain, across
    # A flake's edge: where the plate field crosses the level of a lifted flake (0.25) or
    # of an older, darker layer beneath (-0.8), a thin shadow line.
    edge = np.maximum(np.exp(-((flakes - 0.25) / 0.04) ** 2), 0.6 * np.exp(-((flakes + 0.8) / 0.05) ** 2))
    orange = np.array([0.42, 0.15, 0.06])
    pale = np.array([0.52, 0.25, 0.11])
    brown = np.array([0.26, 0.12, 0.06])
    shadow = np.array([0.10, 0.045, 0.025])
    colour = mix(orange, brown, smoothstep(0.6, 2.0, -tint) * 0.7)
    colour = mix(colour, pale, smoothstep(0.25, 0.6, flakes) * 0.6)
    colour = mix(colour, brown, smoothstep(-0.8, -1.1, flakes) * 0.5)
    colour = mix(colour, shadow, 0.6 * edge)
    colour *= (1.0 + 0.05 * grain)[..., None]
    return to_u8(srgb_encode(colour))


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    out_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "presets", "textures")
    os.makedirs(out_dir, exist_ok=True)
    bark_albedo, bark_height = make_bark(SIZE)
    cactus_albedo, cactus_height = make_cactus(SIZE)
    stone_albedo, stone_height = make_stone(SIZE)
    tiles_albedo, tiles_height = make_tiles(SIZE)
    aloe_albedo = make_aloe(SIZE)
    pine_albedo = make_pine_bark(SIZE)
    for name, pixels in (("bark.png", bark_albedo), ("bark_height.png", bark_height),
                         ("cactus.png", cactus_albedo), ("cactus_height.png", cactus_height),
                         ("aloe.png", aloe_albedo), ("pine_bark.png", pine_albedo),
                         ("stone.png", stone_albedo), ("stone_height.png", stone_height),
                         ("tiles.png", tiles_albedo), ("tiles_height.png", tiles_height)):
        path = os.path.join(out_dir, name)
        write_png(path, pixels)
        print(f"{os.path.normpath(path)}: {pixels.shape[1]}x{pixels.shape[0]}, {os.path.getsize(path)} bytes")


if __name__ == "__main__":
    main()
