"""Grammar.grow(): equal to `sylva grow`, exact 64-bit seeds, defines, threads."""
import json
import subprocess
import threading

import numpy as np
import pytest

import sylva

U64_MAX = 2**64 - 1


def cli_grow(binary, tmp_path, *args):
    out = tmp_path / "cli.skel.json"
    subprocess.run([binary, "grow", *args, "-o", str(out)], check=True, capture_output=True)
    return out.read_text()


@pytest.mark.parametrize("preset, args, kwargs", [
    ("presets/elm.lsys", ["--seed", "7"], {"seed": 7}),
    ("presets/pine.lsys", ["--seed", "3", "-n", "5"], {"seed": 3, "steps": 5}),
    ("presets/saguaro.lsys", ["-D", "ARMS=2", "--seed", str(U64_MAX)], {"defines": {"ARMS": 2}, "seed": U64_MAX}),
])
def test_grow_json_equals_cli_byte_for_byte(sylva_binary, tmp_path, preset, args, kwargs):
    g = sylva.Grammar.from_file(preset)
    if "defines" in kwargs:
        assert set(kwargs["defines"]) <= set(g.defines), "the test names a define the preset lacks"
    sk = g.grow(**kwargs)
    assert sk.to_json() == cli_grow(sylva_binary, tmp_path, preset, *args)


def test_seed_2_to_the_64_minus_1_round_trips_exactly():
    g = sylva.Grammar.from_file("presets/elm.lsys")
    sk = g.grow(seed=U64_MAX)
    assert sk.seed == U64_MAX and type(sk.seed) is int
    assert json.loads(sk.to_json())["source"]["seed"] == U64_MAX
    assert sylva.Skeleton.from_json(sk.to_json()).seed == U64_MAX


def test_seeds_that_differ_only_below_double_precision_give_different_plants():
    # 2**60 and 2**60 + 1 are the same double: a seed through a float would collide.
    g = sylva.Grammar.from_file("presets/elm.lsys")
    a, b = g.grow(seed=2**60), g.grow(seed=2**60 + 1)
    assert (a.seed, b.seed) == (2**60, 2**60 + 1)
    assert a.to_json() != b.to_json()


def test_numpy_integer_seeds_are_accepted_exactly():
    g = sylva.Grammar.from_file("presets/elm.lsys")
    assert g.grow(seed=np.uint64(U64_MAX)).seed == U64_MAX


@pytest.mark.parametrize("seed", [-1, 2**64, -(2**70)])
def test_out_of_range_seeds_raise_overflow_error(seed):
    g = sylva.Grammar.from_file("presets/elm.lsys")
    with pytest.raises(OverflowError, match=r"2\*\*64"):
        g.grow(seed=seed)


@pytest.mark.parametrize("seed", [7.0, "7", True])
def test_non_integer_seeds_raise_type_error(seed):
    g = sylva.Grammar.from_file("presets/elm.lsys")
    with pytest.raises(TypeError, match="seed must be an int"):
        g.grow(seed=seed)


@pytest.mark.parametrize("steps", [7.0, "7", None.__class__])
def test_non_integer_steps_raise_type_error_naming_steps(steps):
    g = sylva.Grammar.from_file("presets/elm.lsys")
    with pytest.raises(TypeError, match="steps must be an int"):
        g.grow(steps=steps)


def test_negative_steps_raise_value_error():
    with pytest.raises(ValueError):
        sylva.Grammar.from_file("presets/elm.lsys").grow(steps=-1)


def test_grow_defaults_come_from_the_grammar():
    g = sylva.Grammar.from_file("presets/elm.lsys")
    sk = g.grow()
    assert (sk.seed, sk.steps, sk.grammar, sk.defines) == (g.seed, g.steps, "presets/elm.lsys", {})


def test_same_inputs_give_identical_skeletons():
    g = sylva.Grammar.from_file("presets/elm.lsys")
    assert g.grow(seed=11).to_json() == g.grow(seed=11).to_json()


def test_defines_change_the_plant_and_are_recorded():
    g = sylva.Grammar.from_file("presets/elm.lsys")
    base = g.grow(seed=7)
    fewer = g.grow(seed=7, defines={"LIMBS": 2})
    assert fewer.defines == {"LIMBS": 2.0}
    assert json.loads(fewer.to_json())["source"]["defines"] == {"LIMBS": 2}
    assert fewer.joint_count != base.joint_count
    # The grammar itself is unchanged: the next grow without defines is the base plant.
    assert g.grow(seed=7).to_json() == base.to_json()
    assert g.defines["LIMBS"] != 2


def test_grow_runs_in_threads_without_deadlock():
    g = sylva.Grammar.from_file("presets/pine.lsys")
    expected = {seed: g.grow(seed=seed).to_json() for seed in (1, 2, 3, 4)}
    results, errors = {}, []

    def work(seed):
        try:
            results[seed] = g.grow(seed=seed).to_json()
        except Exception as e:  # noqa: BLE001 - reported below
            errors.append(e)

    threads = [threading.Thread(target=work, args=(seed,)) for seed in expected]
    for t in threads:
        t.start()
    ticks = 0
    while any(t.is_alive() for t in threads) and ticks < 10**7:
        ticks += 1  # the main thread keeps running Python while the others grow
    for t in threads:
        t.join(timeout=120)
        assert not t.is_alive(), "a grow thread did not finish"
    assert not errors
    assert results == expected


def test_grow_from_text_records_the_given_file_name():
    g = sylva.Grammar("axiom: F\nF -> F[+F]F\n", file="mine.lsys")
    sk = g.grow(steps=2)
    assert sk.grammar == "mine.lsys"
    assert sk.segment_count == 9


# ~10^6 modules rewritten for 100,000 steps: hours, unless Ctrl-C stops it.
_LONG_GRAMMAR = ("derivation length: 100000\naxiom: A(0)\nproductions:\n"
                 "p1: A(n) : n < 20 -> A(n+1)A(n+1)\np2: A(n) : n >= 20 -> A(n)\n")


@pytest.mark.parametrize("method", ["grow", "derive"])
def test_ctrl_c_stops_a_long_derivation_with_keyboard_interrupt(interrupted, method):
    """Issue 32, item 12: grow()/derive() run with the GIL released; their progress reports
    run Python's signal handlers, so Ctrl-C raises KeyboardInterrupt within a step (before:
    only after the whole derivation)."""
    interrupted(f"g = sylva.Grammar({_LONG_GRAMMAR!r}, file='long.lsys')", f"g.{method}()", 0.5)
