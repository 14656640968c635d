"""sylva.export_gltf: files the Khronos validator accepts, with the skeleton in extras."""
import json
import struct

import pytest

import sylva


@pytest.fixture(scope="module")
def saguaro():
    return sylva.Grammar.from_file("presets/saguaro.lsys").grow(seed=5)


def glb_json(path):
    data = path.read_bytes()
    magic, version, length = struct.unpack_from("<4sII", data, 0)
    assert (magic, version, length) == (b"glTF", 2, len(data))
    chunk_length, chunk_type = struct.unpack_from("<II", data, 12)
    assert chunk_type == 0x4E4F534A  # "JSON"
    return json.loads(data[20:20 + chunk_length])


@pytest.mark.parametrize("name, mesh", [("plant.glb", False), ("plant.glb", True),
                                        ("plant.gltf", False), ("plant.gltf", True)])
def test_export_writes_a_file_the_validator_accepts(saguaro, tmp_path, validate_gltf, name, mesh):
    path = tmp_path / name
    sylva.export_gltf(saguaro, path, mesh=mesh, segments_around=6)
    validate_gltf(path)


def test_glb_starts_with_gltf_magic_and_carries_the_skeleton_in_extras(saguaro, tmp_path):
    path = tmp_path / "saguaro.glb"
    sylva.export_gltf(saguaro, str(path))
    doc = glb_json(path)
    nodes = [n for n in doc["nodes"] if "sylva" in n.get("extras", {})]
    assert len(nodes) == 1 and nodes[0]["name"] == "saguaro"
    extras = nodes[0]["extras"]["sylva"]
    assert extras["source"]["seed"] == "5"  # a string: 64-bit exact
    assert len(extras["chains"]) == saguaro.chain_count


def test_a_scene_of_several_plants_with_placement(saguaro, tmp_path, validate_gltf):
    pine = sylva.Grammar.from_file("presets/pine.lsys").grow(seed=1, steps=4)
    path = tmp_path / "scene.glb"
    sylva.export_gltf([saguaro, pine], path, names=["cactus", "tree"], positions=[(0, 0, 0), (5, 0, 2)],
                      rotate_y_deg=[0, 45], scales=[1, 0.5])
    doc = glb_json(path)
    assert {n.get("name") for n in doc["nodes"]} >= {"cactus", "tree"}
    validate_gltf(path)


def test_bad_arguments_raise_before_writing(saguaro, tmp_path):
    path = tmp_path / "x.glb"
    with pytest.raises(ValueError):
        sylva.export_gltf(saguaro, path, segments_around=2)
    with pytest.raises(ValueError):
        sylva.export_gltf([saguaro, saguaro], path, names=["only one"])
    with pytest.raises(ValueError):
        sylva.export_gltf([], path)
    with pytest.raises(TypeError):
        sylva.export_gltf("saguaro", path)
    with pytest.raises(TypeError):
        sylva.export_gltf(saguaro, path, True)  # knobs are keyword-only
    assert not path.exists()


def test_export_failure_raises_with_the_reason(saguaro, tmp_path):
    with pytest.raises(RuntimeError):
        sylva.export_gltf(saguaro, tmp_path / "no_such_dir" / "x.glb")


def test_instancing_of_identical_plants_is_valid(saguaro, tmp_path, validate_gltf):
    path = tmp_path / "instanced.glb"
    sylva.export_gltf([saguaro, saguaro, saguaro], path, instancing=True, positions=[(0, 0, 0), (3, 0, 0), (6, 0, 0)])
    assert path.read_bytes()[:4] == b"glTF"
    validate_gltf(path)
