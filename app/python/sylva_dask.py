"""sylva_dask — batches of seeds on a dask.distributed cluster, writing what the local batch writes.

The command line grows or exports many seeds of one grammar in one command
(``sylva grow GRAMMAR --seed A..B -o out/elm_{seed}.skel.json``, docs/spec/cli.md); when a dataset
outgrows one machine, this module hands the same seeds to the workers of a
``dask.distributed`` cluster instead. Each seed is one task: the worker grows the plant
with the ``sylva`` module (the same code as the command line) and writes its file
atomically, so the files are byte for byte those of the local batch — whichever worker
wrote them, in whatever order. Nothing but a path comes back to the client: skeletons
and meshes stay on the workers.

    from dask.distributed import Client, LocalCluster
    import sylva_dask

    with LocalCluster(n_workers=2, threads_per_worker=1) as cluster, Client(cluster) as client:
        written = sylva_dask.batch(client, "grow", "presets/elm.lsys", range(1, 101),
                                   "out/elm_{seed}.skel.json")

Requirements: the workers import ``sylva`` (the module built for the same Python; put
``build/release/python`` on their ``PYTHONPATH``) and see the output folder (a shared
file system on a real cluster). The grammar's text travels with the tasks, so workers
need not see the grammar file; its path is recorded in each skeleton as given here, as
the command line records the path it was given (run both from the same folder for
identical files).

The frames of an animated scene go the same way (``sylva render SCENE --frames A..B -o
out/f_{frame}.png``, docs/animation.md): one task per frame, each running the ``sylva``
command line for its one frame, so every file is the one the local command writes —
same code, same bytes — whichever worker rendered it:

    with LocalCluster(n_workers=2, threads_per_worker=1) as cluster, Client(cluster) as client:
        written = sylva_dask.frames(client, "presets/scenes/dancing_cacti.scene.json", range(0, 96),
                                    "out/cacti/f_{frame}.png", sylva="build/release/app/cli/sylva")

The workers need the ``sylva`` executable (``sylva=`` or ``$SYLVA_BINARY`` or PATH) and
must see the scene, what it names (grammars, textures) and the output folder.
"""
import os
import shutil
import subprocess

__all__ = ["batch", "frames", "output_path", "frame_path", "KINDS"]

#: What a task writes: "grow" a sylva-skeleton JSON file (``sylva grow``), "export" a glTF
#: 2.0 file, .gltf or .glb by the pattern's extension (``sylva export``).
KINDS = ("grow", "export")
EXTRAS = ("compact", "full", "none")  # sylva export --extras (docs/gltf.md)


def output_path(pattern, seed):
    """The file of one seed: ``{seed}`` in ``pattern`` replaced by the decimal seed (docs/spec/cli.md)."""
    if "{seed}" not in pattern:
        raise ValueError(f"the output pattern {pattern!r} has no {{seed}}: every seed would write the same file")
    if "{seed}" not in os.path.normpath(pattern):
        raise ValueError(f"the output pattern {pattern!r}: '..' undoes the folder {{seed}} names, "
                         f"so every seed would write {os.path.normpath(pattern)!r}")
    return pattern.replace("{seed}", str(seed))


def _seed_task(kind, text, grammar_path, seed, path, steps, defines, export_options):
    """One seed on a worker: grow, write atomically (the sylva writers), return the path."""
    import sylva  # on the worker

    grammar = sylva.Grammar(text, file=grammar_path)
    skeleton = grammar.grow(seed=seed, steps=steps, defines=defines)
    folder = os.path.dirname(path)
    if folder:
        os.makedirs(folder, exist_ok=True)  # `{seed}` may name a folder
    if kind == "grow":
        skeleton.save(path)
    else:
        sylva.export_gltf(skeleton, path, **export_options)
    return path


def batch(client, kind, grammar, seeds, output, *, steps=None, defines=None, mesh=False, segments_around=8,
          extras="compact", rig=False, max_joints=128, animation=None, wind_data=False, lod=0, compress="none"):
    """Grows (``kind="grow"``) or exports (``kind="export"``) every seed of ``grammar`` on the
    workers of ``client`` (a ``dask.distributed.Client``), one task per seed, into
    ``output`` with ``{seed}`` replaced. Returns the paths written, in the order of ``seeds``.

    ``steps`` and ``defines`` are ``sylva grow``'s ``-n`` and ``-D``; ``mesh``,
    ``segments_around``, ``extras``, ``rig``, ``max_joints``, ``animation`` (True or a dict of
    a scene's animation keys), ``wind_data``, ``lod`` and ``compress`` are ``sylva.export_gltf``'s (docs/gltf.md), with
    its defaults (``extras`` is ``"compact"`` here, as ``sylva export --extras``, so the files
    are the CLI batch's).
    The grammar is parsed here first, so a bad grammar raises ``sylva.GrammarError`` before
    any task is sent; a task that fails raises its exception here (the files of the seeds
    that finished stay: each is complete).

    Raises ``ValueError`` for an unknown kind, an unknown ``extras``, a pattern without
    ``{seed}`` or repeated seeds (two tasks would race for one file), ``TypeError`` /
    ``OverflowError`` for a seed that is not an integer in [0, 2**64 - 1] (as ``Grammar.grow``).
    """
    import sylva

    if kind not in KINDS:
        raise ValueError(f"unknown kind {kind!r}: expected one of {', '.join(KINDS)}")
    if extras not in EXTRAS:
        raise ValueError(f"unknown extras {extras!r}: expected one of {', '.join(EXTRAS)}")
    seeds = list(seeds)
    if len(set(seeds)) != len(seeds):
        raise ValueError("a seed is repeated: its tasks would write the same file")
    for seed in seeds:
        if isinstance(seed, bool) or not hasattr(seed, "__index__"):
            raise TypeError(f"a seed is an integer, not {type(seed).__name__}")
        if not 0 <= int(seed) < 2**64:
            raise OverflowError(f"seed {int(seed)} is outside [0, 2**64 - 1]")
    seeds = [int(s) for s in seeds]
    parsed = sylva.Grammar.from_file(grammar)  # errors here, located, before any task
    if defines:
        parsed.grow(steps=0, defines=defines)  # unknown define names, bad values: here too
    paths = [output_path(output, seed) for seed in seeds]
    export_options = dict(mesh=mesh, segments_around=segments_around, extras=extras, rig=rig,
                          max_joints=max_joints, animation=animation, wind_data=wind_data, lod=lod,
                          compress=compress)
    futures = client.map(_seed_task, [kind] * len(seeds), [parsed.text] * len(seeds), [parsed.file] * len(seeds),
                         seeds, paths, [steps] * len(seeds), [defines] * len(seeds), [export_options] * len(seeds),
                         pure=False)
    return client.gather(futures)


def frame_path(pattern, frame):
    """The file of one frame: ``{frame}`` in ``pattern`` replaced by the frame number with at
    least four digits (``f_0007.png``), as ``sylva render --frames`` names it."""
    if "{frame}" not in pattern:
        raise ValueError(f"the output pattern {pattern!r} has no {{frame}}: every frame would write the same file")
    return pattern.replace("{frame}", f"{frame:04d}")


def _sylva_binary(sylva):
    """The command line the frame tasks run: ``sylva``, else $SYLVA_BINARY, else PATH's."""
    path = sylva or os.environ.get("SYLVA_BINARY") or shutil.which("sylva")
    if not path:
        raise FileNotFoundError("no sylva executable: pass sylva=PATH, set SYLVA_BINARY or put sylva on PATH")
    return os.path.abspath(path) if os.sep in path else path


def _frame_task(binary, scene, frame, pattern, path, arguments):
    """One frame on a worker: ``sylva render SCENE --frames F -o PATTERN ...``; its path."""
    done = subprocess.run([binary, "render", scene, "--frames", str(frame), "-o", pattern, *arguments],
                          capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"sylva render {scene} --frames {frame} failed ({done.returncode}): {done.stderr.strip()}")
    return path


def frames(client, scene, frame_numbers, output, *, backend="cpu", spp=None, width=None, height=None,
           fps=None, sylva=None):
    """Renders the frames ``frame_numbers`` of the animated ``scene`` (a .scene.json with an
    ``animation`` key) on the workers of ``client``, one task per frame, into ``output``
    with ``{frame}`` replaced (frame_path). Returns the paths written, in the order given.

    ``backend`` (default "cpu", the reference, whose frames depend only on their number),
    ``spp``, ``width``, ``height`` and ``fps`` are ``sylva render``'s flags. Every frame's
    file is what ``sylva render SCENE --frames A..B -o OUTPUT`` with the same flags writes
    for it. A frame that fails raises RuntimeError with the command's message here (the
    frames that finished stay: each is written atomically).

    Raises ``ValueError`` for a pattern without ``{frame}``, repeated frames (two tasks
    would race for one file) or a scene file that does not exist, ``TypeError`` for a frame
    that is not an integer, ``FileNotFoundError`` when there is no ``sylva`` executable.
    """
    frame_numbers = list(frame_numbers)
    for frame in frame_numbers:
        if isinstance(frame, bool) or not hasattr(frame, "__index__"):
            raise TypeError(f"a frame is an integer, not {type(frame).__name__}")
        if int(frame) < 0:
            raise ValueError(f"frame {int(frame)} is negative")
    frame_numbers = [int(f) for f in frame_numbers]
    if len(set(frame_numbers)) != len(frame_numbers):
        raise ValueError("a frame is repeated: its tasks would write the same file")
    paths = [frame_path(output, f) for f in frame_numbers]
    if not os.path.isfile(scene):
        raise ValueError(f"{scene}: no such scene file")
    binary = _sylva_binary(sylva)
    arguments = ["--backend", backend]
    for flag, value in (("--spp", spp), ("--width", width), ("--height", height), ("--fps", fps)):
        if value is not None:
            arguments += [flag, str(value)]
    futures = client.map(_frame_task, [binary] * len(frame_numbers), [os.path.abspath(scene)] * len(frame_numbers),
                         frame_numbers, [os.path.abspath(output)] * len(frame_numbers),
                         [os.path.abspath(p) for p in paths], [arguments] * len(frame_numbers), pure=False)
    client.gather(futures)  # raises a failed frame's error here
    return paths
