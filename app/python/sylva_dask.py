"""sylva_dask — batches of seeds on a dask.distributed cluster, writing what the local batch writes.

The command line grows or exports many seeds of one grammar in one command
(``sylva grow GRAMMAR --seed A..B -o out/elm_{seed}.skel.json``, cli.md); when a dataset
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
"""
import os

__all__ = ["batch", "output_path", "KINDS"]

#: What a task writes: "grow" a sylva-skeleton JSON file (``sylva grow``), "export" a glTF
#: 2.0 file, .gltf or .glb by the pattern's extension (``sylva export``).
KINDS = ("grow", "export")


def output_path(pattern, seed):
    """The file of one seed: ``{seed}`` in ``pattern`` replaced by the decimal seed (cli.md)."""
    if "{seed}" not in pattern:
        raise ValueError(f"the output pattern {pattern!r} has no {{seed}}: every seed would write the same file")
    return pattern.replace("{seed}", str(seed))


def _seed_task(kind, text, grammar_path, seed, path, steps, defines, mesh, segments_around):
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
        sylva.export_gltf(skeleton, path, mesh=mesh, segments_around=segments_around)
    return path


def batch(client, kind, grammar, seeds, output, *, steps=None, defines=None, mesh=False, segments_around=8):
    """Grows (``kind="grow"``) or exports (``kind="export"``) every seed of ``grammar`` on the
    workers of ``client`` (a ``dask.distributed.Client``), one task per seed, into
    ``output`` with ``{seed}`` replaced. Returns the paths written, in the order of ``seeds``.

    ``steps`` and ``defines`` are ``sylva grow``'s ``-n`` and ``-D``; ``mesh`` and
    ``segments_around`` are ``sylva export``'s. The grammar is parsed here first, so a bad
    grammar raises ``sylva.GrammarError`` before any task is sent; a task that fails raises
    its exception here (the files of the seeds that finished stay: each is complete).

    Raises ``ValueError`` for an unknown kind, a pattern without ``{seed}`` or repeated
    seeds (two tasks would race for one file), ``TypeError``/``OverflowError`` for a seed
    that is not an integer in [0, 2**64 - 1] (as ``Grammar.grow``).
    """
    import sylva

    if kind not in KINDS:
        raise ValueError(f"unknown kind {kind!r}: expected one of {', '.join(KINDS)}")
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
    futures = client.map(_seed_task, [kind] * len(seeds), [parsed.text] * len(seeds), [parsed.file] * len(seeds),
                         seeds, paths, [steps] * len(seeds), [defines] * len(seeds), [mesh] * len(seeds),
                         [segments_around] * len(seeds), pure=False)
    return client.gather(futures)
