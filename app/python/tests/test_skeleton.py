"""sylva.Skeleton: zero-copy read-only numpy views, segments, chains, files."""
import gc
import json
import pickle

import numpy as np
import pytest

import sylva


@pytest.fixture(scope="module")
def elm():
    return sylva.Grammar.from_file("presets/elm.lsys").grow(seed=7)


def test_shapes_and_dtypes(elm):
    j, s, c = elm.joint_count, elm.segment_count, elm.chain_count
    assert elm.positions.shape == (j, 3) and elm.positions.dtype == np.float64
    assert elm.radii.shape == (j,) and elm.radii.dtype == np.float64
    assert elm.materials.shape == (j,) and elm.materials.dtype == np.uint32
    assert elm.segments.shape == (s, 2) and elm.segments.dtype == np.int32
    assert elm.chains.shape == (c,)
    assert elm.chains.dtype.names == ("first_joint", "joint_count", "parent_chain", "parent_joint")
    assert all(elm.chains.dtype[name] == np.int32 for name in elm.chains.dtype.names)
    assert s == int((elm.chains["joint_count"] - 1).sum())


def test_views_match_the_json(elm):
    doc = json.loads(elm.to_json())
    joints = np.array([joint for chain in doc["chains"] for joint in chain["joints"]])
    np.testing.assert_array_equal(elm.positions, joints[:, :3])
    np.testing.assert_array_equal(elm.radii, joints[:, 3])
    np.testing.assert_array_equal(elm.materials, joints[:, 4].astype(np.uint32))
    parents = [chain["parent"] or [-1, -1] for chain in doc["chains"]]
    np.testing.assert_array_equal(np.stack([elm.chains["parent_chain"], elm.chains["parent_joint"]], 1), parents)


def test_views_are_read_only(elm):
    for view in (elm.positions, elm.radii, elm.materials):
        assert not view.flags.writeable
        with pytest.raises(ValueError):
            view[0] = 1
        with pytest.raises(ValueError):
            view.setflags(write=True)


def test_views_are_zero_copy(elm):
    def address(a):
        return a.__array_interface__["data"][0]
    assert address(elm.positions) == address(elm.positions)
    assert address(elm.radii) - address(elm.positions) == 24  # one Joint record: x y z radius material
    assert elm.positions.strides == (40, 8)
    assert not elm.positions.flags.owndata


def test_a_view_keeps_the_skeleton_alive():
    sk = sylva.Grammar.from_file("presets/pine.lsys").grow(seed=2)
    expected = np.array(sk.positions)  # a copy
    radii_sum = float(sk.radii.sum())
    positions, radii = sk.positions, sk.radii
    del sk
    gc.collect()
    _ = [np.zeros(1000) for _ in range(100)]  # churn the allocator
    np.testing.assert_array_equal(positions, expected)
    assert float(radii.sum()) == radii_sum
    assert isinstance(positions.base, sylva.Skeleton) or isinstance(positions.base.base, sylva.Skeleton)


def test_segments_join_consecutive_joints_and_branches_start_at_the_parent_joint(elm):
    segments, chains = elm.segments, elm.chains
    row = 0
    for c in chains:
        first, count = int(c["first_joint"]), int(c["joint_count"])
        for k in range(1, count):
            start = first + k - 1
            if k == 1 and c["parent_chain"] >= 0:
                start = int(chains[c["parent_chain"]]["first_joint"] + c["parent_joint"])
                # the parent joint stands where the branch's first joint stands
                np.testing.assert_array_equal(elm.positions[start], elm.positions[first])
            assert tuple(segments[row]) == (start, first + k)
            row += 1
    assert row == len(segments)


def test_chains_parents_come_before_children(elm):
    c = elm.chains
    assert c["parent_chain"][0] == -1
    children = c["parent_chain"] >= 0
    assert (c["parent_chain"][children] < np.nonzero(children)[0]).all()
    assert (c["parent_joint"][children] < c["joint_count"][c["parent_chain"][children]]).all()


def test_save_and_from_file_round_trip(elm, tmp_path):
    path = tmp_path / "elm.skel.json"
    elm.save(path)
    assert path.read_text() == elm.to_json()
    again = sylva.Skeleton.from_file(str(path))
    assert again.to_json() == elm.to_json()
    assert (again.seed, again.steps, again.grammar) == (7, elm.steps, "presets/elm.lsys")


def test_pickle_round_trips(elm):
    assert pickle.loads(pickle.dumps(elm)).to_json() == elm.to_json()


def test_invalid_skeleton_json_raises_skeleton_error_with_a_place():
    text = '{"format": "sylva-skeleton", "version": 1, "source": {"grammar": "x", "seed": 1, "steps": 1, ' \
           '"defines": {}}, "chains": [{"parent": null, "joints": [[0,0,0, -1, 0]]}]}'
    with pytest.raises(sylva.SkeletonError) as info:
        sylva.Skeleton.from_json(text, "neg.skel.json")
    e = info.value
    assert isinstance(e, ValueError)
    assert e.file == "neg.skel.json" and e.line == 1 and e.column > 1
    assert "radius" in str(e)


def test_missing_skeleton_file_raises_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError):
        sylva.Skeleton.from_file(tmp_path / "none.skel.json")


def test_repr_names_grammar_seed_and_counts(elm):
    r = repr(elm)
    assert "elm.lsys" in r and "seed=7" in r and f"{elm.segment_count} segments" in r


def test_leaves_are_arrays_matching_the_json():
    # docs/spec/grammar.md's polygons become leaves (docs/spec/skeleton.md "Leaves", version 2).
    sk = sylva.Grammar("angle: 60\naxiom: F[&F'(1){.+f.-f.-f.}]F{.+f.-f.-f.+|+f.-f.}\n").grow()
    assert sk.leaf_count == 2
    assert sk.leaves.dtype.names == ("first_vertex", "vertex_count", "chain", "joint", "material", "back_material")
    assert sk.leaves.dtype["material"] == np.uint32
    doc = json.loads(sk.to_json())
    assert doc["version"] == 2
    np.testing.assert_array_equal(sk.leaves["vertex_count"], [len(leaf["vertices"]) for leaf in doc["leaves"]])
    np.testing.assert_array_equal(sk.leaves["first_vertex"], [0, len(doc["leaves"][0]["vertices"])])
    np.testing.assert_array_equal(sk.leaves["material"], [leaf["material"] for leaf in doc["leaves"]])
    # One material on both sides: the back's is the front's (a cpfg double-sided leaf's differs).
    np.testing.assert_array_equal(sk.leaves["back_material"], sk.leaves["material"])
    joints = [leaf["joint"] or [-1, -1] for leaf in doc["leaves"]]
    np.testing.assert_array_equal(np.stack([sk.leaves["chain"], sk.leaves["joint"]], 1), joints)
    np.testing.assert_array_equal(sk.leaf_vertices, [v for leaf in doc["leaves"] for v in leaf["vertices"]])
    assert sk.leaf_vertices.shape == (sum(sk.leaves["vertex_count"]), 3)


def test_a_double_sided_leafs_back_material_is_its_own():
    # docs/leaves.md "Two colours": a leaf with a `back_material` (a cpfg double-sided
    # surface's) shows it in the records; the leaf without one keeps its front's.
    sk = sylva.Grammar("angle: 60\naxiom: F[&F'(1){.+f.-f.-f.}]F{.+f.-f.-f.+|+f.-f.}\n").grow()
    doc = json.loads(sk.to_json())
    doc["leaves"][1]["back_material"] = 5
    two = sylva.Skeleton.from_json(json.dumps(doc), "two.skel.json")
    np.testing.assert_array_equal(two.leaves["material"], sk.leaves["material"])
    np.testing.assert_array_equal(two.leaves["back_material"], [sk.leaves["material"][0], 5])
    assert json.loads(two.to_json())["leaves"][1]["back_material"] == 5


def test_a_skeleton_without_leaves_has_empty_leaf_arrays(elm):
    assert elm.leaf_count == 0
    assert elm.leaves.shape == (0,) and elm.leaf_vertices.shape == (0, 3)


def test_save_never_overwrites_the_grammar_the_plant_grew_from(tmp_path):
    # Issue 32 item 5: the CLI refuses `grow mine.lsys -o mine.lsys`; so does Python, under
    # any name for the same file (a hard link here), and the grammar stays as it was.
    grammar = tmp_path / "mine.lsys"
    text = open("presets/elm.lsys").read()
    grammar.write_text(text)
    (tmp_path / "alias.lsys").hardlink_to(grammar)
    sk = sylva.Grammar.from_file(str(grammar)).grow(seed=7)
    for target in (grammar, tmp_path / "alias.lsys"):
        with pytest.raises(OSError, match="of this call, which writing would destroy"):
            sk.save(target)
        with pytest.raises(OSError, match="of this call, which writing would destroy"):
            sylva.export_gltf(sk, target)
    assert grammar.read_text() == text
    sk.save(tmp_path / "mine.skel.json")  # any other file is written
    assert sylva.Skeleton.from_file(tmp_path / "mine.skel.json").to_json() == sk.to_json()


@pytest.mark.parametrize("make, use", [
    (lambda: sylva.Skeleton.__new__(sylva.Skeleton), lambda o: o.to_json()),
    (lambda: sylva.Skeleton.__new__(sylva.Skeleton), lambda o: o.positions),
    (lambda: sylva.Skeleton.__new__(sylva.Skeleton), lambda o: o.joint_count),
    (lambda: sylva.Skeleton.__new__(sylva.Skeleton), repr),
    (lambda: sylva.Skeleton.__new__(sylva.Skeleton), lambda o: sylva.export_gltf([o], "never.glb")),
    (lambda: sylva.Skeleton.__new__(sylva.Skeleton), lambda o: sylva.render(o, width=8, height=8)),
    (lambda: sylva.Grammar.__new__(sylva.Grammar), lambda o: o.grow()),
    (lambda: sylva.Grammar.__new__(sylva.Grammar), lambda o: o.derive()),
])
def test_an_object_made_by_new_without_init_raises_type_error(make, use, tmp_path, monkeypatch):
    # Issue 32 item 8: these crashed the interpreter (uninitialised memory).
    monkeypatch.chdir(tmp_path)
    with pytest.raises(TypeError, match="made by __new__ without __init__"):
        use(make())
    assert list(tmp_path.iterdir()) == []
