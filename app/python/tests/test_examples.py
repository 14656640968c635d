"""The examples in app/python/examples run, with small sizes, and write what they say."""
import os
import pathlib
import struct
import subprocess
import sys
import zlib

import numpy as np
import pytest

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"


def run_example(name, *args):
    done = subprocess.run([sys.executable, str(EXAMPLES / name), *args], capture_output=True, text=True,
                          env=dict(os.environ), timeout=300)
    assert done.returncode == 0, done.stdout + done.stderr
    return done.stdout


def read_png_rgb8(path):
    """The pixels of an 8-bit RGB PNG with filter 0 rows (what define_sweep.py writes)."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack_from(">I4s", data, pos)
        body = data[pos + 8:pos + 8 + length]
        assert struct.unpack_from(">I", data, pos + 8 + length)[0] == zlib.crc32(kind + body)
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, colour_type = header[:4]
    assert (depth, colour_type) == (8, 2)
    rows = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(height, 1 + width * 3)
    assert (rows[:, 0] == 0).all()
    return rows[:, 1:].reshape(height, width, 3)


def test_forest_writes_one_glb_per_plant_and_a_forest(tmp_path, validate_gltf):
    out = tmp_path / "forest"
    run_example("forest.py", "--grammar", "presets/elm.lsys", "--count", "5", "--first-seed", "10", "--out", str(out))
    names = sorted(p.name for p in out.iterdir())
    assert names == ["elm_10.glb", "elm_11.glb", "elm_12.glb", "elm_13.glb", "elm_14.glb", "forest.glb"]
    assert all((out / n).read_bytes()[:4] == b"glTF" for n in names)
    assert (out / "elm_10.glb").read_bytes() != (out / "elm_11.glb").read_bytes()  # varied seeds
    validate_gltf(out / "forest.glb")


@pytest.mark.parametrize("draw", ["lines", "render"])
def test_define_sweep_writes_a_contact_sheet(tmp_path, draw):
    png = tmp_path / "sweep.png"
    out = run_example("define_sweep.py", "--grammar", "presets/saguaro.lsys", "--define", "ARMS",
                      "--values", "0", "2", "4", "--cell", "40x60", "--draw", draw, "-o", str(png))
    assert "ARMS = 0, 2, 4" in out
    pixels = read_png_rgb8(png)
    assert pixels.shape == (2 * 60, 2 * 40, 3)  # 3 cells on a 2x2 grid
    cells = [pixels[r * 60 + 1:(r + 1) * 60, c * 40 + 1:(c + 1) * 40] for r, c in [(0, 0), (0, 1), (1, 0)]]
    assert all(len(np.unique(cell.reshape(-1, 3), axis=0)) > 1 for cell in cells)  # a plant in each
    assert not np.array_equal(cells[0], cells[2])  # the define changes the plant


def test_define_sweep_rejects_a_define_the_grammar_lacks(tmp_path):
    done = subprocess.run([sys.executable, str(EXAMPLES / "define_sweep.py"), "--define", "NOPE",
                           "-o", str(tmp_path / "x.png")], capture_output=True, text=True)
    assert done.returncode == 2 and "no #define NOPE" in done.stderr
