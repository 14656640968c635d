"""sylva.render: the CPU ray caster on a skeleton or a scene, as numpy (and a file)."""
import os
import subprocess

import numpy as np
import pytest

import sylva


@pytest.fixture(scope="module")
def saguaro():
    return sylva.Grammar.from_file("presets/saguaro.lsys").grow(seed=5)


def test_render_returns_height_width_rgba_float32(saguaro):
    img = sylva.render(saguaro, width=48, height=32)
    assert img.shape == (32, 48, 4) and img.dtype == np.float32
    assert np.isfinite(img).all()
    np.testing.assert_array_equal(img[..., 3], 1.0)
    assert img[..., :3].std() > 0  # a plant, ground and sky: not one flat colour


def test_render_is_the_same_for_any_thread_count(saguaro):
    a = sylva.render(saguaro, width=40, height=30, threads=1)
    b = sylva.render(saguaro, width=40, height=30, threads=2)
    np.testing.assert_array_equal(a, b)


def test_render_takes_sylva_renders_default_of_eight_samples_per_pixel(saguaro):
    default = sylva.render(saguaro, width=40, height=30)
    np.testing.assert_array_equal(default, sylva.render(saguaro, width=40, height=30, spp=8))
    assert not np.array_equal(default, sylva.render(saguaro, width=40, height=30, spp=1))


def test_render_rejects_unknown_backends_and_empty_images(saguaro):
    with pytest.raises(ValueError):
        sylva.render(saguaro, backend="vulkan")
    with pytest.raises(ValueError):
        sylva.render(saguaro, width=0, height=10)


def test_render_refuses_sizes_and_samples_beyond_the_limits_before_allocating(saguaro):
    # docs/limits.md: 65536 per side, 2**26 pixels, 65536 samples per pixel.
    with pytest.raises(ValueError, match="pixels"):
        sylva.render(saguaro, width=65536, height=65536)
    with pytest.raises(ValueError, match="on each side"):
        sylva.render(saguaro, width=65537, height=1)
    with pytest.raises(ValueError, match="samples per pixel"):
        sylva.render(saguaro, width=4, height=4, spp=4_000_000_000)


def test_render_and_export_take_the_papers_skin(saguaro, tmp_path):
    # docs/spec/scene.md "Skin": skin="paper" is `--skin paper`; the default is smooth.
    smooth = sylva.render(saguaro, width=64, height=48, spp=1)
    np.testing.assert_array_equal(smooth, sylva.render(saguaro, width=64, height=48, spp=1, skin="smooth"))
    paper = sylva.render(saguaro, width=64, height=48, spp=1, skin="paper")
    assert not np.array_equal(smooth, paper)
    with pytest.raises(ValueError, match='skin must be "smooth" or "paper"'):
        sylva.render(saguaro, width=8, height=8, skin="mitred")
    out = tmp_path / "paper.gltf"
    sylva.export_gltf(saguaro, out, mesh=True, skin="paper")
    assert '"skin":"paper"' in out.read_text()
    with pytest.raises(ValueError, match="skin must be"):
        sylva.export_gltf(saguaro, tmp_path / "x.glb", skin="Paper")
    assert not (tmp_path / "x.glb").exists()


def test_ctrl_c_stops_a_long_render_with_keyboard_interrupt(interrupted):
    """render() runs Python's signal handlers while its workers render: Ctrl-C cancels the
    render between tiles and raises KeyboardInterrupt (before: only once it finished)."""
    interrupted("sk = sylva.Grammar.from_file('presets/saguaro.lsys').grow(seed=5)",
                "sylva.render(sk, width=4096, height=4096, spp=4096)", 1.0)  # hours unless stopped


def test_render_takes_a_scene_a_camera_a_sun_and_writes_the_image(tmp_path, sylva_binary):
    """Issue 31 §6: render took only a skeleton, with a fixed camera, and wrote nothing."""
    scene = "presets/scenes/saguaro.scene.json"
    img = sylva.render(scene, width=48, height=36, spp=1)
    assert img.shape == (36, 48, 4) and np.isfinite(img).all()
    # The CLI's flags, the same picture byte for byte.
    out = tmp_path / "s.png"
    again = sylva.render(scene, width=48, height=36, spp=1, eye=(0, 3, 15), target=(0, 3, 0), fov_y_deg=30,
                         sun=(1, 0.3, 0), output=out)
    assert not np.array_equal(img, again)
    cli = tmp_path / "cli.png"
    r = subprocess.run([sylva_binary, "render", scene, "-o", str(cli),
                        "--width", "48", "--height", "36", "--spp", "1", "--backend", "cpu", "--eye", "0,3,15",
                        "--target", "0,3,0", "--fov", "30", "--sun", "1,0.3,0"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert out.read_bytes() == cli.read_bytes()
    # Bad arguments name themselves; nothing is written; never onto the scene.
    with pytest.raises(ValueError, match="camera"):
        sylva.render(scene, width=8, height=8, eye=(0, 3, 0), target=(0, 3, 0))
    with pytest.raises(TypeError, match="eye must be an"):
        sylva.render(scene, width=8, height=8, eye="above")
    with pytest.raises(ValueError, match="sun"):
        sylva.render(scene, width=8, height=8, sun=(0, 0, 0))
    with pytest.raises(ValueError, match="not a .scene.json"):
        sylva.render("presets/elm.lsys", width=8, height=8)
    with pytest.raises(TypeError, match="render takes a sylva.Skeleton or the path"):
        sylva.render(42)
    with pytest.raises(FileNotFoundError):
        sylva.render(str(tmp_path / "missing.scene.json"))
    copy = tmp_path / "copy.scene.json"
    copy.write_text(open(scene).read().replace('"../', '"' + os.path.abspath("presets") + '/'))
    before = copy.read_bytes()
    with pytest.raises(OSError):
        sylva.render(copy, width=8, height=8, spp=1, output=copy)
    assert copy.read_bytes() == before
