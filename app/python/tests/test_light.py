"""Light queries from Python (docs/spec/light.md): Grammar.grow/derive(scene=...) and
grow_with_queries(), equal to `sylva grow|derive --scene`."""
import subprocess

import numpy as np
import pytest

import sylva

APEX = """module: A
derivation length: 6
axiom: A ?E(1, 0, 0, 0)
A > ?E(q, x, y, z) : q > 0.5 -> F(0.5) A
"""

CANOPY = "axiom: f(1.6) &(90) f(1) { . +(90) f(1) . +(90) f(2) . +(90) f(2) . +(90) f(2) . +(90) f(1) . }\n"


def shade_scene(tmp_path):
    (tmp_path / "canopy.lsys").write_text(CANOPY)
    scene = tmp_path / "shade.scene.json"
    scene.write_text('{"format": "sylva-scene", "version": 1, '
                     '"sun": {"direction": [0, 1, 0], "angular_radius_deg": 0.27}, '
                     '"environment": {"photons": 200000, "sensor_radius_m": 0.05}, '
                     '"plants": [{"grammar": "canopy.lsys"}]}\n')
    return scene


def test_grow_with_queries_gives_positions_answers_and_directions():
    g = sylva.Grammar(APEX, file="apex.lsys")
    sk, queries = g.grow_with_queries()
    assert queries.shape == (1, 7) and queries.dtype == np.float64
    x, y, z, q, dx, dy, dz = queries[0]
    # Alone in the default sun the apex climbs all six steps: the query is at its tip, 3 m up.
    assert (x, y, z) == (0.0, 3.0, 0.0)
    assert 0.5 < q <= 1.0
    assert dy > 0.8 and abs(np.hypot(dx, np.hypot(dy, dz)) - 1) < 1e-9  # toward the sun, above
    assert len(sk.segments) == 6


def test_a_scene_shades_the_grammar_as_the_cli_does(sylva_binary, tmp_path):
    scene = shade_scene(tmp_path)
    grammar = tmp_path / "apex.lsys"
    grammar.write_text(APEX)
    g = sylva.Grammar.from_file(str(grammar))
    word = g.derive(scene=scene)
    assert word == "A?E(0,0,0,0)"  # under the canopy from the start: it never grows
    cli = subprocess.run([sylva_binary, "derive", str(grammar), "--scene", str(scene)], check=True,
                         capture_output=True, text=True).stdout
    assert cli == word + "\n"
    sk, queries = g.grow_with_queries(scene=str(scene))
    assert len(sk.segments) == 0 and queries[0, 3] == 0.0


def test_a_grammar_without_queries_has_none_and_bad_scenes_raise(tmp_path):
    sk, queries = sylva.Grammar("axiom: F F\n").grow_with_queries()
    assert queries.shape == (0, 7)
    with pytest.raises(TypeError):
        sylva.Grammar(APEX).grow(scene=3)
    with pytest.raises(OSError):
        sylva.Grammar(APEX).grow(scene=tmp_path / "missing.scene.json")
    bad = tmp_path / "bad.scene.json"
    bad.write_text('{"format": "sylva-scene", "version": 1, "environment": {"photons": 0}, "plants": []}\n')
    with pytest.raises(ValueError, match="environment.photons"):
        sylva.Grammar(APEX).grow(scene=bad)
