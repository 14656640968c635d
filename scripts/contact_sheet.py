#!/usr/bin/python3
"""contact_sheet.py — tiles rendered pictures into one labelled PNG (docs/images/presets.png).

    /usr/bin/python3 scripts/contact_sheet.py OUT.png COLUMNS IMAGE LABEL [IMAGE LABEL]...

Each IMAGE is an 8-bit PNG as `sylva render -o X.png` writes it, all of one size; each LABEL is written under its picture, each '|' starting a new line (three at
most), in a
5 x 7 pixel font drawn at twice its size where the line fits the picture's width, else
at its size (lower-case letters, digits and _ , . ( ) : - /; anything else is a blank).
Needs numpy only (no OpenImageIO, ImageMagick or PIL: none is installed on the shared
machine); the PNG is written with zlib and struct.
"""
import struct
import sys
import zlib

import numpy as np

# 5 x 7 glyphs, one string of 7 rows of 5 columns each ('#' ink).
_GLYPHS = {
    'a': "     |     | ### |    #| ####|#   #| ####", 'b': "#    |#    |#### |#   #|#   #|#   #|#### ",
    'c': "     |     | ####|#    |#    |#    | ####", 'd': "    #|    #| ####|#   #|#   #|#   #| ####",
    'e': "     |     | ### |#   #|#####|#    | ### ", 'f': "  ## | #   |#### | #   | #   | #   | #   ",
    'g': "     |     | ####|#   #| ####|    #| ### ", 'h': "#    |#    |#### |#   #|#   #|#   #|#   #",
    'i': "  #  |     | ##  |  #  |  #  |  #  | ### ", 'j': "   # |     |  ## |   # |   # |#  # | ##  ",
    'k': "#    |#    |#  # |# #  |##   |# #  |#  # ", 'l': " ##  |  #  |  #  |  #  |  #  |  #  | ### ",
    'm': "     |     |## # |# # #|# # #|# # #|# # #", 'n': "     |     |#### |#   #|#   #|#   #|#   #",
    'o': "     |     | ### |#   #|#   #|#   #| ### ", 'p': "     |     |#### |#   #|#### |#    |#    ",
    'q': "     |     | ####|#   #| ####|    #|    #", 'r': "     |     |# ## |##   |#    |#    |#    ",
    's': "     |     | ####|#    | ### |    #|#### ", 't': " #   | #   |#### | #   | #   | #   |  ## ",
    'u': "     |     |#   #|#   #|#   #|#   #| ####", 'v': "     |     |#   #|#   #|#   #| # # |  #  ",
    'w': "     |     |#   #|# # #|# # #|# # #| # # ", 'x': "     |     |#   #| # # |  #  | # # |#   #",
    'y': "     |     |#   #|#   #| ####|    #| ### ", 'z': "     |     |#####|   # |  #  | #   |#####",
    '0': " ### |#   #|#  ##|# # #|##  #|#   #| ### ", '1': "  #  | ##  |  #  |  #  |  #  |  #  | ### ",
    '2': " ### |#   #|    #|   # |  #  | #   |#####", '3': "#####|   # |  #  |   # |    #|#   #| ### ",
    '4': "   # |  ## | # # |#  # |#####|   # |   # ", '5': "#####|#    |#### |    #|    #|#   #| ### ",
    '6': "  ## | #   |#    |#### |#   #|#   #| ### ", '7': "#####|    #|   # |  #  | #   | #   | #   ",
    '8': " ### |#   #|#   #| ### |#   #|#   #| ### ", '9': " ### |#   #|#   #| ####|    #|   # | ##  ",
    '_': "     |     |     |     |     |     |#####", ',': "     |     |     |     |  ## |   # |  #  ",
    '.': "     |     |     |     |     |  ## |  ## ", '(': "   # |  #  | #   | #   | #   |  #  |   # ",
    ')': " #   |  #  |   # |   # |   # |  #  | #   ", ':': "     |  ## |  ## |     |  ## |  ## |     ",
    '-': "     |     |     |#####|     |     |     ", '/': "     |    #|   # |  #  | #   |#    |     ",
}


def glyph(c):
    rows = _GLYPHS.get(c.lower(), "     |     |     |     |     |     |     ").split('|')
    return np.array([[ch == '#' for ch in row] for row in rows], dtype=bool)


def draw_text(canvas, x, y, text, scale=2, colour=(20, 20, 20)):
    """Writes `text` with its top-left corner at (x, y), clipped to the canvas."""
    for k, c in enumerate(text):
        mask = np.kron(glyph(c), np.ones((scale, scale), dtype=bool))
        x0 = x + k * 6 * scale
        h, w = mask.shape
        region = canvas[y:y + h, x0:x0 + w]
        m = mask[:region.shape[0], :region.shape[1]]
        region[m] = colour


def read_png(path):
    """An 8-bit, non-interlaced RGB or RGBA PNG (what `sylva render -o X.png` writes) as an
    H x W x 3 uint8 array (alpha dropped). The filters are undone row by row (RFC 2083 6)."""
    data = open(path, 'rb').read()
    if data[:8] != b'\x89PNG\r\n\x1a\n':
        raise SystemExit(f"{path}: not a PNG")
    pos, idat, header = 8, [], None
    while pos < len(data):
        (n,), kind = struct.unpack('>I', data[pos:pos + 4]), data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + n]
        if kind == b'IHDR':
            header = struct.unpack('>IIBBBBB', body)
        elif kind == b'IDAT':
            idat.append(body)
        pos += 12 + n
    w, h, depth, colour, _, _, interlace = header
    if depth != 8 or colour not in (2, 6) or interlace:
        raise SystemExit(f"{path}: only 8-bit non-interlaced RGB or RGBA PNGs are read")
    bpp = 3 if colour == 2 else 4
    raw, stride = zlib.decompress(b''.join(idat)), w * bpp
    out = bytearray(h * stride)
    prev = bytearray(stride)
    for y in range(h):
        kind, row = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        if kind == 1:
            for x in range(bpp, stride):
                row[x] = (row[x] + row[x - bpp]) & 255
        elif kind == 2:
            row = bytearray((a + b) & 255 for a, b in zip(row, prev))
        elif kind == 3:
            for x in range(stride):
                row[x] = (row[x] + (((row[x - bpp] if x >= bpp else 0) + prev[x]) >> 1)) & 255
        elif kind == 4:
            for x in range(stride):
                a, b = (row[x - bpp] if x >= bpp else 0), prev[x]
                c = prev[x - bpp] if x >= bpp else 0
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                row[x] = (row[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        out[y * stride:(y + 1) * stride] = row
        prev = row
    return np.frombuffer(bytes(out), dtype=np.uint8).reshape(h, w, bpp)[:, :, :3]


def write_png(path, rgb):
    """An 8-bit RGB PNG (filter 0 on every row; the picture is small)."""
    h, w, _ = rgb.shape
    raw = b''.join(b'\x00' + rgb[y].tobytes() for y in range(h))
    def chunk(kind, body):
        return struct.pack('>I', len(body)) + kind + body + struct.pack('>I', zlib.crc32(kind + body) & 0xffffffff)
    png = b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, 8, 2, 0, 0, 0))
    png += chunk(b'IDAT', zlib.compress(raw, 9)) + chunk(b'IEND', b'')
    with open(path + '.tmp', 'wb') as f:  # atomically, as sylva writes its outputs
        f.write(png)
    import os
    os.replace(path + '.tmp', path)


def main(argv):
    if len(argv) < 5 or (len(argv) - 3) % 2:
        raise SystemExit(__doc__)
    out, columns = argv[1], int(argv[2])
    items = [(argv[i], argv[i + 1]) for i in range(3, len(argv), 2)]
    pictures = [read_png(path) for path, _ in items]
    h, w, _ = pictures[0].shape
    if any(p.shape != pictures[0].shape for p in pictures):
        raise SystemExit("contact_sheet.py: the pictures must all have one size")
    label_h, gap = 50, 4
    rows = (len(items) + columns - 1) // columns
    sheet = np.full((rows * (h + label_h + gap) + gap, columns * (w + gap) + gap, 3), 245, dtype=np.uint8)
    for k, (picture, (_, label)) in enumerate(zip(pictures, items)):
        x = gap + (k % columns) * (w + gap)
        y = gap + (k // columns) * (h + label_h + gap)
        sheet[y:y + h, x:x + w] = picture
        for line, text in enumerate(label.split('|')[:3]):
            scale = 2 if len(text) * 12 <= w - 2 else 1
            # Clipped to the tile: a line too long for it is cut at its edge.
            draw_text(sheet[:, :x + w], x + 2, y + h + 3 + 16 * line, text, scale)
    write_png(out, sheet)


if __name__ == '__main__':
    main(sys.argv)
