"""sylva.export_gltf: files the Khronos validator accepts, with the skeleton in extras."""
import json
import os
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


def test_a_mesh_that_cannot_fit_is_a_value_error_before_anything_is_written(tmp_path):
    pine = sylva.Grammar.from_file("presets/pine.lsys").grow(seed=1)
    path = tmp_path / "huge.glb"
    with pytest.raises(ValueError, match="the mesh would take"):
        sylva.export_gltf(pine, path, mesh=True, segments_around=4096)
    assert not path.exists()


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


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"names": [3]}, r"names\[0\] must be a str, got int"),
        ({"positions": ["abc"]}, r"positions\[0\] must be an \(x, y, z\) sequence of numbers, got str"),
        ({"rotate_y_deg": ["a"]}, r"rotate_y_deg\[0\] must be a number \(degrees\), got str"),
        ({"scales": [None]}, r"scales\[0\] must be a number, got NoneType"),
        ({"mesh": True, "bark": {"albedo": 3}}, r"bark\['albedo'\] must be a path or an \(r, g, b\) linear colour, got int"),
        ({"mesh": True, "bark": {"height": 2.5}}, r"bark\['height'\] must be a path, got float"),
        ({"mesh": True, "bark": {"relief_depth": "x"}}, r"bark\['relief_depth'\] must be a number \(metres\), got str"),
        ({"mesh": True, "bark": {"u_repeat": [1]}}, r"bark\['u_repeat'\] must be a number, got list"),
    ],
)
def test_a_value_of_the_wrong_type_is_a_type_error_naming_the_argument(saguaro, tmp_path, kwargs, message):
    # Issue 32: these were RuntimeError "Unable to cast Python instance to C++ type".
    path = tmp_path / "x.glb"
    with pytest.raises(TypeError, match=message):
        sylva.export_gltf([saguaro], path, **kwargs)
    assert not path.exists()


def test_export_failure_raises_with_the_reason(saguaro, tmp_path):
    # The README's promise: OSError for files, ValueError for values, never RuntimeError.
    with pytest.raises(FileNotFoundError):
        sylva.export_gltf(saguaro, tmp_path / "no_such_dir" / "x.glb")
    fifo = tmp_path / "fifo.glb"
    os.mkfifo(fifo)
    with pytest.raises(OSError, match="it is a FIFO"):
        sylva.export_gltf(saguaro, fifo)
    far = sylva.Skeleton.from_json(
        '{"format": "sylva-skeleton", "version": 1, "chains": '
        '[{"parent": null, "joints": [[0,0,0,0.1,0],[1e300,0,0,0.1,0]]}]}')
    with pytest.raises(ValueError, match="beyond the limit of 1e12 m"):
        sylva.export_gltf(far, tmp_path / "far.glb")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fifo.glb"]


def test_instancing_of_identical_plants_is_valid(saguaro, tmp_path, validate_gltf):
    path = tmp_path / "instanced.glb"
    sylva.export_gltf([saguaro, saguaro, saguaro], path, instancing=True, positions=[(0, 0, 0), (3, 0, 0), (6, 0, 0)])
    assert path.read_bytes()[:4] == b"glTF"
    validate_gltf(path)


def test_a_textured_bark_gives_materials_with_textures_and_tangents(tmp_path, validate_gltf, repo):
    # The bark is the wood's (docs/materials.md): SKIN = 0 makes the whole cactus wood.
    saguaro = sylva.Grammar.from_file("presets/saguaro.lsys").grow(seed=5, defines={"SKIN": 0})
    bark = dict(albedo=repo / "presets/textures/cactus.png", height=str(repo / "presets/textures/cactus_height.png"),
                relief_depth=0.01, u_repeat=12, v_per_metre=4)
    for name in ("bark.glb", "bark.gltf"):
        path = tmp_path / name
        sylva.export_gltf(saguaro, path, mesh=True, segments_around=6, bark=bark)
        validate_gltf(path)
    doc = glb_json(tmp_path / "bark.glb")
    assert len(doc["images"]) == 2
    for material in doc["materials"]:
        assert material["name"].startswith("sylva_material_")
        assert "baseColorTexture" in material["pbrMetallicRoughness"] and "normalTexture" in material
        extras = material["extras"]["sylva"]
        assert (extras["u_repeat"], extras["v_per_metre"], extras["relief_depth_m"]) == (12, 4, 0.01)
        assert extras["height"].endswith("cactus_height.png") and extras["r_ref_m"] > 0
    triangles = [p for p in doc["meshes"][0]["primitives"] if p["mode"] == 4]
    assert triangles and all("TANGENT" in p["attributes"] for p in triangles)


def test_bark_colour_and_bark_errors(saguaro, tmp_path):
    pine = sylva.Grammar.from_file("presets/pine.lsys").grow(seed=1, steps=4)  # wood (0) and needles (1)
    path = tmp_path / "colour.glb"
    sylva.export_gltf(pine, path, mesh=True, bark={"albedo": (0.5, 0.4, 0.3)})
    materials = {m["extras"]["sylva"]["material_index"]: m for m in glb_json(path)["materials"]}
    assert materials[0]["pbrMetallicRoughness"]["baseColorFactor"] == [0.5, 0.4, 0.3, 1]
    assert materials[1]["pbrMetallicRoughness"]["baseColorFactor"] == [0.16, 0.34, 0.1, 1]  # the table's
    out = tmp_path / "x.glb"
    with pytest.raises(OSError, match="no_such_bark.png"):
        sylva.export_gltf(saguaro, out, mesh=True, bark={"albedo": str(tmp_path / "no_such_bark.png")})
    with pytest.raises(ValueError):
        sylva.export_gltf(saguaro, out, bark={"u_repeat": 2})  # needs mesh=True
    with pytest.raises(ValueError):
        sylva.export_gltf(saguaro, out, mesh=True, bark={"u_repeats": 2})
    with pytest.raises(ValueError):
        sylva.export_gltf(saguaro, out, mesh=True, bark={"v_per_metre": 0})
    with pytest.raises(TypeError):
        sylva.export_gltf(saguaro, out, mesh=True, bark="presets/textures/bark.png")
    assert not out.exists()


def glb_chunks(path):
    data = path.read_bytes()
    json_length = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20:20 + json_length])
    bin_length = struct.unpack_from("<I", data, 20 + json_length)[0]
    return doc, data[28 + json_length:28 + json_length + bin_length]


def test_compact_extras_hold_the_exact_doubles_in_buffer_views(saguaro, tmp_path, validate_gltf):
    import numpy as np
    path = tmp_path / "compact.glb"
    sylva.export_gltf(saguaro, path, extras="compact")
    validate_gltf(path)
    doc, binary = glb_chunks(path)
    extras = doc["nodes"][0]["extras"]["sylva"]
    assert extras["source"]["seed"] == "5" and extras["chains"]["count"] == saguaro.chain_count
    view = doc["bufferViews"][extras["chains"]["joints"]]
    joints = np.frombuffer(binary, "<f8", view["byteLength"] // 8, view.get("byteOffset", 0)).reshape(-1, 4)
    assert np.array_equal(joints[:, :3], saguaro.positions) and np.array_equal(joints[:, 3], saguaro.radii)
    full = tmp_path / "full.glb"
    sylva.export_gltf(saguaro, full)  # the default here: every number as JSON
    assert isinstance(glb_json(full)["nodes"][0]["extras"]["sylva"]["chains"], list)
    assert path.stat().st_size < full.stat().st_size


def test_extras_none_writes_no_node_extras_and_a_bad_mode_is_a_value_error(saguaro, tmp_path):
    path = tmp_path / "plain.glb"
    sylva.export_gltf(saguaro, path, extras="none")
    assert "extras" not in glb_json(path)["nodes"][0]
    with pytest.raises(ValueError, match="extras must be"):
        sylva.export_gltf(saguaro, tmp_path / "x.glb", extras="tiny")
    assert not (tmp_path / "x.glb").exists()


def test_a_rig_with_a_wind_clip_and_wind_data(saguaro, tmp_path, validate_gltf):
    path = tmp_path / "windy.glb"
    sylva.export_gltf(saguaro, path, mesh=True, rig=True, max_joints=16,
                      animation={"wind": [1, 0, 1], "duration_s": 2, "fps": 10, "seed": 3}, wind_data=True)
    doc = glb_json(path)
    assert len(doc["skins"]) == 1 and 2 <= len(doc["skins"][0]["joints"]) <= 16
    clip = doc["animations"][0]
    assert clip["name"] == "wind" and clip["channels"]
    times = doc["accessors"][clip["samplers"][0]["input"]]
    assert times["count"] == 21 and times["max"] == [2]
    skinned = [n for n in doc["nodes"] if "skin" in n]
    attributes = doc["meshes"][skinned[0]["mesh"]]["primitives"][0]["attributes"]
    assert {"JOINTS_0", "WEIGHTS_0", "TEXCOORD_1", "TEXCOORD_2", "TEXCOORD_3"} <= set(attributes)
    validate_gltf(path)
    # True: the default sway (4 s at 24 fps).
    sylva.export_gltf(saguaro, path, mesh=True, rig=True, animation=True)
    doc = glb_json(path)
    assert doc["accessors"][doc["animations"][0]["samplers"][0]["input"]]["count"] == 97


def test_rig_arguments_are_checked_and_nothing_is_written(saguaro, tmp_path):
    path = tmp_path / "refused.glb"
    with pytest.raises(ValueError, match="export the mesh too"):
        sylva.export_gltf(saguaro, path, rig=True)
    with pytest.raises(ValueError, match="max_joints must be from 1 to 1024"):
        sylva.export_gltf(saguaro, path, mesh=True, rig=True, max_joints=0)
    with pytest.raises(ValueError, match="export the rig too"):
        sylva.export_gltf(saguaro, path, mesh=True, animation=True)
    with pytest.raises(ValueError, match="animation.fps"):
        sylva.export_gltf(saguaro, path, mesh=True, rig=True, animation={"fps": -1})
    with pytest.raises(TypeError, match="animation must be"):
        sylva.export_gltf(saguaro, path, mesh=True, rig=True, animation="breezy")
    assert not path.exists()


def test_levels_of_detail_end_in_textured_cards(saguaro, tmp_path, validate_gltf):
    path = tmp_path / "lod.glb"
    sylva.export_gltf(saguaro, path, mesh=True, lod=2)
    doc = glb_json(path)
    names = [n["name"] for n in doc["nodes"]]
    assert {"saguaro_LOD0", "saguaro_LOD1", "saguaro_LOD2"} <= set(names)
    assert len(doc["images"]) == 2  # the two cards
    validate_gltf(path)
    with pytest.raises(ValueError, match="lod must be from 0"):
        sylva.export_gltf(saguaro, tmp_path / "x.glb", mesh=True, lod=7)


def test_meshopt_compression_is_required_and_smaller(saguaro, tmp_path):
    plain, packed = tmp_path / "plain.glb", tmp_path / "packed.glb"
    sylva.export_gltf(saguaro, plain, mesh=True)
    sylva.export_gltf(saguaro, packed, mesh=True, compress="meshopt")
    doc = glb_json(packed)
    assert doc["extensionsRequired"] == ["EXT_meshopt_compression"]
    assert packed.stat().st_size < 0.8 * plain.stat().st_size
    assert "extensionsRequired" not in glb_json(plain)
    with pytest.raises(ValueError, match="compress must be"):
        sylva.export_gltf(saguaro, tmp_path / "x.glb", mesh=True, compress="zip")
