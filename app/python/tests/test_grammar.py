"""sylva.Grammar: parsing text and files, errors as GrammarError, derive()."""
import pathlib
import subprocess

import pytest

import sylva

SIMPLE = """\
#define ANGLE 30
angle: ANGLE
derivation length: 2
axiom: F
F -> F[+F]F[-F]F
"""


def test_grammar_from_text_keeps_text_file_name_and_defaults():
    g = sylva.Grammar(SIMPLE, file="simple.lsys")
    assert g.text == SIMPLE
    assert g.file == "simple.lsys"
    assert g.defines == {"ANGLE": 30.0}
    assert g.steps == 2
    assert g.seed == 1
    assert "simple.lsys" in repr(g)


def test_grammar_from_text_names_it_string_by_default():
    assert sylva.Grammar(SIMPLE).file == "<string>"


def test_grammar_from_file_accepts_str_and_pathlike():
    a = sylva.Grammar.from_file("presets/elm.lsys")
    b = sylva.Grammar.from_file(pathlib.Path("presets/elm.lsys"))
    assert a.file == b.file == "presets/elm.lsys"
    assert a.text == pathlib.Path("presets/elm.lsys").read_text()
    assert "LIMBS" in a.defines


def test_grammar_from_file_takes_a_cpfg_model_and_a_vlab_object_folder():
    # docs/cpfg.md: both grow the plant of their .lsys twin, and -D works on both.
    twin = sylva.Grammar.from_file("presets/abop_1_24d.lsys").grow(defines={"N": 3})
    model = sylva.Grammar.from_file("presets/cpfg/abop_1_24d.l")
    folder = sylva.Grammar.from_file("presets/cpfg/abop_1_24d_object")
    assert folder.file == "presets/cpfg/abop_1_24d_object"
    assert "Lsystem: 1" in folder.text  # the object's model
    assert model.defines["N"] == 7.0 and folder.defines["N"] == 7.0
    for g in (model, folder):
        grown = g.grow(defines={"N": 3})
        assert grown.positions.shape == twin.positions.shape
        assert (grown.positions == twin.positions).all()
        assert abs(grown.radii - twin.radii).max() < 1e-15
    with pytest.raises(sylva.GrammarError) as info:
        sylva.Grammar.from_file("presets/cpfg")  # a folder without specifications
    assert "not a vlab object" in str(info.value)


def test_a_vlab_object_whose_model_needs_its_view_file(tmp_path):
    # Its function set's names are macros only with the view file: the model alone would
    # not parse (docs/cpfg.md "Functions"); from_file reads the object as a whole.
    (tmp_path / "specifications").write_text("generate:\n\tcpfg plant.l plant.v\n")
    (tmp_path / "shapes.fset").write_text(
        "funcgalleryver 1 1\nitems: 1\nfver 1 1\nname: LINE\nsamples: 0\nflip: off\npoints: 4\n"
        "0 0\n0.3333 0.3333\n0.6667 0.6667\n1 1\n")
    (tmp_path / "plant.v").write_text("function set: shapes.fset\nangle factor: 4\n")
    (tmp_path / "plant.l").write_text("Lsystem: 1\nderivation length: 1\nAxiom: A\n"
                                      "A --> F(1 + func(LINE, 0.5))\nendlsystem\n")
    g = sylva.Grammar.from_file(str(tmp_path))
    assert g.file == str(tmp_path)
    tip = g.grow().positions.max(axis=0)
    assert abs(tip[1] - 1.5) < 2e-3  # func(LINE, 0.5) = 0.5, within cpfg's bisection tolerance


def test_grammar_from_missing_file_raises_file_not_found():
    with pytest.raises(FileNotFoundError) as info:
        sylva.Grammar.from_file("presets/no_such_plant.lsys")
    assert "no_such_plant.lsys" in str(info.value)


def test_grammar_error_is_a_value_error_with_file_line_and_column():
    bad = "axiom: F\nF -> F[+F\n"
    with pytest.raises(sylva.GrammarError) as info:
        sylva.Grammar(bad, file="bad.lsys")
    e = info.value
    assert isinstance(e, ValueError)
    assert (e.file, e.line, e.column) == ("bad.lsys", 2, 7)
    assert e.message == "unbalanced brackets in the successor: '[' is never closed"
    assert e.source_line == "F -> F[+F"
    # str() is the CLI's diagnostic: located first line, source line, caret.
    assert str(e).splitlines() == ["bad.lsys:2:7: error: " + e.message, "F -> F[+F", "      ^"]


def test_unknown_define_is_a_grammar_error_without_a_place():
    g = sylva.Grammar(SIMPLE, file="simple.lsys")
    with pytest.raises(sylva.GrammarError) as info:
        g.grow(defines={"ANGEL": 10})
    assert info.value.line is None and info.value.column is None
    assert info.value.file == "simple.lsys"
    assert "ANGEL" in str(info.value)


def test_defines_must_be_numbers_keyed_by_name():
    g = sylva.Grammar(SIMPLE)
    with pytest.raises(TypeError):
        g.grow(defines={"ANGLE": "thirty"})
    with pytest.raises(TypeError):
        g.grow(defines={1: 2})
    with pytest.raises(ValueError):
        g.grow(defines={"ANGLE": float("nan")})


def test_knobs_are_keyword_only():
    g = sylva.Grammar(SIMPLE)
    with pytest.raises(TypeError):
        g.grow(3)  # steps must be named
    with pytest.raises(TypeError):
        g.derive(3)


def test_derive_returns_the_printed_word():
    g = sylva.Grammar("axiom: A\nA -> AB\nB -> A\n")
    assert g.derive(steps=0) == "A"
    assert g.derive(steps=4) == "ABAABABA"


def test_derive_errors_are_grammar_errors():
    g = sylva.Grammar("axiom: A(0)\nA(x) -> A(1/x)\n", file="div.lsys")
    with pytest.raises(sylva.GrammarError) as info:
        g.derive(steps=1)
    assert info.value.file == "div.lsys"


def test_max_modules_stops_runaway_growth_with_grammar_error():
    g = sylva.Grammar("axiom: A\nA -> AA\n")
    with pytest.raises(sylva.GrammarError):
        g.derive(steps=20, max_modules=1000)


def test_derive_equals_cli_derive(sylva_binary):
    g = sylva.Grammar.from_file("presets/abop_1_24a.lsys")
    cli = subprocess.run([sylva_binary, "derive", "presets/abop_1_24a.lsys", "-n", "3"],
                         capture_output=True, check=True).stdout.decode()
    assert g.derive(steps=3) + "\n" == cli


def test_importing_sylva_without_numpy_says_numpy_is_missing(tmp_path):
    """Issue 31 §6: a Python without numpy got "ImportError: initialization failed"."""
    import os
    import subprocess
    import sys
    fake = tmp_path / "numpy"
    fake.mkdir()
    (fake / "__init__.py").write_text("raise ImportError('No module named numpy (hidden by the test)')\n")
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(tmp_path), env.get("PYTHONPATH", "")])
    r = subprocess.run([sys.executable, "-c", "import sylva"], env=env, capture_output=True, text=True, timeout=600)
    assert r.returncode != 0
    assert "ImportError: sylva needs numpy" in r.stderr, r.stderr
    assert "python3-numpy" in r.stderr, r.stderr
