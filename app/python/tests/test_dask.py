"""sylva_dask on a LocalCluster of two worker processes writes, seed for seed, the bytes
that the command line's batch (``--seed A..B``) writes, and refuses bad batches before
sending a task."""
import pathlib
import subprocess

import pytest

distributed = pytest.importorskip("distributed", reason="python3-distributed (scripts/setup.sh installs it)")

import sylva  # noqa: E402
import sylva_dask  # noqa: E402


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
    with cluster, distributed.Client(cluster) as c:
        assert len(c.scheduler_info()["workers"]) == 2
        yield c


def cli_batch(sylva_binary, *args):
    done = subprocess.run([sylva_binary, *args], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr


def assert_same_files(a, b):
    assert len(a) == len(b)
    for x, y in zip(a, b):
        assert pathlib.Path(x).read_bytes() == pathlib.Path(y).read_bytes(), f"{x} differs from {y}"


def test_grow_on_two_workers_writes_the_local_batchs_files(tmp_path, client, sylva_binary):
    cli_batch(sylva_binary, "grow", "presets/elm.lsys", "--seed", "1..6", "-o", str(tmp_path / "cli/elm_{seed}.skel.json"))
    with distributed.get_task_stream(client) as stream:
        written = sylva_dask.batch(client, "grow", "presets/elm.lsys", range(1, 7),
                                   str(tmp_path / "dask/elm_{seed}.skel.json"))
    assert written == [str(tmp_path / f"dask/elm_{s}.skel.json") for s in range(1, 7)]
    assert_same_files(written, [str(tmp_path / f"cli/elm_{s}.skel.json") for s in range(1, 7)])
    # The seeds matter (the elm is stochastic), so equal files are not a coincidence.
    assert len({pathlib.Path(p).read_bytes() for p in written}) == 6
    # The tasks were spread over both workers (idle workers each take a share).
    assert len({task["worker"] for task in stream.data}) == 2


def test_export_with_defines_and_a_seed_folder(tmp_path, client, sylva_binary):
    cli_batch(sylva_binary, "export", "presets/elm.lsys", "--seed", "3..5", "-D", "LIMBS=5", "--mesh",
              "-o", str(tmp_path / "cli/elm_{seed}.glb"))
    written = sylva_dask.batch(client, "export", "presets/elm.lsys", [5, 3, 4], str(tmp_path / "dask/s{seed}/elm.glb"),
                               defines={"LIMBS": 5}, mesh=True)
    assert written == [str(tmp_path / f"dask/s{s}/elm.glb") for s in (5, 3, 4)]  # the folders made
    assert_same_files(written, [str(tmp_path / f"cli/elm_{s}.glb") for s in (5, 3, 4)])
    # extras= is --extras: the full JSON extras are the CLI's too, and differ from the compact.
    cli_batch(sylva_binary, "export", "presets/elm.lsys", "--seed", "3", "--extras", "full",
              "-o", str(tmp_path / "cli/full_{seed}.gltf"))
    full = sylva_dask.batch(client, "export", "presets/elm.lsys", [3], str(tmp_path / "dask/full_{seed}.gltf"),
                            extras="full")
    assert_same_files(full, [str(tmp_path / "cli/full_3.gltf")])
    assert b'"chains":[{' in pathlib.Path(full[0]).read_bytes().replace(b" ", b"").replace(b"\n", b"")
    # The rig, the wind clip and the wind data: the CLI batch's files, byte for byte.
    cli_batch(sylva_binary, "export", "presets/elm.lsys", "--seed", "4", "--mesh", "--rig", "--max-joints", "40",
              "--animation", "--wind-data", "--lod", "2", "--compress", "meshopt", "-o", str(tmp_path / "cli/rig_{seed}.glb"))
    rigged = sylva_dask.batch(client, "export", "presets/elm.lsys", [4], str(tmp_path / "dask/rig_{seed}.glb"),
                              mesh=True, rig=True, max_joints=40, animation=True, wind_data=True, lod=2,
                              compress="meshopt")
    assert_same_files(rigged, [str(tmp_path / "cli/rig_4.glb")])


def test_bad_batches_are_refused_before_any_task(tmp_path, client):
    bad = tmp_path / "bad.lsys"
    bad.write_text("axiom: A\nproductions:\nA -> B(\n")
    with pytest.raises(sylva.GrammarError) as e:
        sylva_dask.batch(client, "grow", str(bad), [1, 2], str(tmp_path / "x_{seed}.skel.json"))
    assert e.value.line == 3
    with pytest.raises(ValueError, match="no \\{seed\\}"):
        sylva_dask.batch(client, "grow", "presets/elm.lsys", [1, 2], str(tmp_path / "same.skel.json"))
    with pytest.raises(ValueError, match="undoes the folder"):
        sylva_dask.batch(client, "grow", "presets/elm.lsys", [1, 2], str(tmp_path / "{seed}" / ".." / "same.skel.json"))
    assert list(tmp_path.iterdir()) == [bad]
    with pytest.raises(ValueError, match="repeated"):
        sylva_dask.batch(client, "grow", "presets/elm.lsys", [1, 1], str(tmp_path / "x_{seed}.skel.json"))
    with pytest.raises(ValueError, match="unknown kind"):
        sylva_dask.batch(client, "render", "presets/elm.lsys", [1], str(tmp_path / "x_{seed}.png"))
    with pytest.raises(ValueError, match="unknown extras"):
        sylva_dask.batch(client, "export", "presets/elm.lsys", [1], str(tmp_path / "x_{seed}.glb"), extras="json")
    with pytest.raises(TypeError):
        sylva_dask.batch(client, "grow", "presets/elm.lsys", [1.5], str(tmp_path / "x_{seed}.skel.json"))
    with pytest.raises(OverflowError):
        sylva_dask.batch(client, "grow", "presets/elm.lsys", [2**64], str(tmp_path / "x_{seed}.skel.json"))
    with pytest.raises(sylva.GrammarError):
        sylva_dask.batch(client, "grow", "presets/elm.lsys", [1], str(tmp_path / "x_{seed}.skel.json"),
                         defines={"NO_SUCH_DEFINE": 1})
    assert not list(tmp_path.glob("x_*")) and not (tmp_path / "same.skel.json").exists()


def test_the_example_runs_a_local_cluster(tmp_path, sylva_binary):
    import os
    import sys
    example = pathlib.Path(__file__).resolve().parents[1] / "examples" / "dask_batch.py"
    done = subprocess.run([sys.executable, str(example), "--seeds", "7..9", "--workers", "2",
                           "-o", str(tmp_path / "d/elm_{seed}.skel.json")], capture_output=True, text=True,
                          env=dict(os.environ), timeout=300)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "3 files from 2 workers" in done.stdout
    cli_batch(sylva_binary, "grow", "presets/elm.lsys", "--seed", "7..9", "-o", str(tmp_path / "c_{seed}.skel.json"))
    assert_same_files([str(tmp_path / f"d/elm_{s}.skel.json") for s in (7, 8, 9)],
                      [str(tmp_path / f"c_{s}.skel.json") for s in (7, 8, 9)])


def small_dancing_scene(tmp_path, repo):
    """The dancing cacti at 64x48, one second at 4 frames per second: frames 0..3."""
    import json
    scene = json.loads((repo / "presets/scenes/dancing_cacti.scene.json").read_text())
    scene["image"] = {"width": 64, "height": 48}
    scene["animation"]["fps"] = 4
    scene["animation"]["duration_s"] = 1
    for plant in scene.get("plants", []):
        plant["grammar"] = str((repo / "presets/scenes" / plant["grammar"]).resolve())
    for entry in scene.get("scatter", []):
        entry["grammar"] = str((repo / "presets/scenes" / entry["grammar"]).resolve())
    for material in scene.get("materials", []):  # image files, relative to the scene
        if isinstance(material.get("albedo"), str):
            material["albedo"] = str((repo / "presets/scenes" / material["albedo"]).resolve())
    path = tmp_path / "dancing.scene.json"
    path.write_text(json.dumps(scene))
    return str(path)


def test_frames_on_two_workers_write_the_local_commands_files(tmp_path, client, sylva_binary, repo):
    scene = small_dancing_scene(tmp_path, repo)
    cli_batch(sylva_binary, "render", scene, "--backend", "cpu", "--frames", "0..3",
              "-o", str(tmp_path / "cli/f_{frame}.png"))
    with distributed.get_task_stream(client) as stream:
        written = sylva_dask.frames(client, scene, [3, 1, 0, 2], str(tmp_path / "dask/f_{frame}.png"),
                                    sylva=sylva_binary)
    assert written == [str(tmp_path / f"dask/f_{f:04d}.png") for f in (3, 1, 0, 2)]
    assert_same_files(written, [str(tmp_path / f"cli/f_{f:04d}.png") for f in (3, 1, 0, 2)])
    # The cacti move between frames, so equal files are not a coincidence.
    assert len({pathlib.Path(p).read_bytes() for p in written}) == 4
    assert len({task["worker"] for task in stream.data}) == 2


def test_frames_refuse_bad_batches_before_any_task(tmp_path, client, sylva_binary, repo):
    scene = small_dancing_scene(tmp_path, repo)
    with pytest.raises(ValueError, match="no {frame}"):
        sylva_dask.frames(client, scene, [0], str(tmp_path / "f.png"), sylva=sylva_binary)
    with pytest.raises(ValueError, match="repeated"):
        sylva_dask.frames(client, scene, [1, 1], str(tmp_path / "f_{frame}.png"), sylva=sylva_binary)
    with pytest.raises(TypeError):
        sylva_dask.frames(client, scene, [1.5], str(tmp_path / "f_{frame}.png"), sylva=sylva_binary)
    with pytest.raises(ValueError, match="no such scene"):
        sylva_dask.frames(client, str(tmp_path / "none.scene.json"), [0], str(tmp_path / "f_{frame}.png"),
                          sylva=sylva_binary)
    assert not list(tmp_path.glob("f_*.png"))


def test_a_failing_frame_raises_the_commands_message(tmp_path, client, sylva_binary, repo):
    still = tmp_path / "empty.scene.json"  # nothing moves or grows: --frames refuses it
    still.write_text('{"plants": []}')
    with pytest.raises(RuntimeError, match="--frames 0 failed"):
        sylva_dask.frames(client, str(still), [0], str(tmp_path / "f_{frame}.png"), sylva=sylva_binary)


def test_the_frames_example_renders_a_scenes_frames(tmp_path, sylva_binary, repo):
    scene = small_dancing_scene(tmp_path, repo)
    example = pathlib.Path(__file__).resolve().parents[1] / "examples" / "dask_batch.py"
    import os
    import sys
    done = subprocess.run([sys.executable, str(example), "--scene", scene, "--frames", "1..2",
                           "-o", str(tmp_path / "ex/f_{frame}.png"), "--sylva", sylva_binary, "--workers", "2"],
                          capture_output=True, text=True, env=dict(os.environ), timeout=300)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "2 files from 2 workers" in done.stdout
    assert (tmp_path / "ex/f_0001.png").is_file() and (tmp_path / "ex/f_0002.png").is_file()
