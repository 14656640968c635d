#!/usr/bin/python3
"""dask_batch.py — grow or export many seeds of a grammar, or render the frames of an animated scene, on a dask.distributed cluster.

The files are those the command line's batch writes (`sylva grow GRAMMAR --seed A..B -o
PATTERN`; with --scene and --frames, `sylva render SCENE --frames A..B -o PATTERN`), byte
for byte: one task per seed or frame, each written atomically by a worker. Without
--scheduler a LocalCluster of --workers processes on this machine stands in for a cluster.

    PYTHONPATH=build/release/python /usr/bin/python3 app/python/examples/dask_batch.py \
        --grammar presets/elm.lsys --seeds 1..100 -o out/elm_{seed}.skel.json
    PYTHONPATH=build/release/python /usr/bin/python3 app/python/examples/dask_batch.py \
        --scene presets/scenes/dancing_cacti.scene.json --frames 0..95 -o out/cacti/f_{frame}.png \
        --sylva build/release/app/sylva
    # on a cluster: dask-scheduler on one machine, dask-worker ADDRESS on the others
    #               (with the sylva module on their PYTHONPATH; for frames, the sylva
    #               executable and the scene's files too), then --scheduler ADDRESS
"""
import argparse
import time

from dask.distributed import Client, LocalCluster

import sylva_dask


def seed_range(text):
    """A..B (or one number): seeds or frames."""
    first, sep, last = text.partition("..")
    if not sep:
        return [int(text)]
    a, b = int(first), int(last)
    if b < a:
        raise argparse.ArgumentTypeError(f"{text}: the last number is below the first")
    return list(range(a, b + 1))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grammar", default="presets/elm.lsys")
    parser.add_argument("--seeds", type=seed_range, default=seed_range("1..8"), help="A..B (default 1..8)")
    parser.add_argument("--kind", choices=sylva_dask.KINDS, default="grow")
    parser.add_argument("-o", "--output", default="dask_out/elm_{seed}.skel.json", help="pattern with {seed}")
    parser.add_argument("-D", dest="defines", action="append", default=[], metavar="NAME=VALUE")
    parser.add_argument("--mesh", action="store_true", help="export: the skinned mesh too")
    parser.add_argument("--scene", help="render this animated scene's --frames instead of growing seeds")
    parser.add_argument("--frames", type=seed_range, default=seed_range("0..7"), help="A..B (default 0..7)")
    parser.add_argument("--sylva", help="frames: the sylva executable (default: $SYLVA_BINARY, else PATH)")
    parser.add_argument("--scheduler", help="a running cluster's scheduler address (default: a LocalCluster)")
    parser.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes (default 2)")
    args = parser.parse_args(argv)
    defines = {}
    for d in args.defines:
        name, sep, value = d.partition("=")
        if not sep:
            parser.error(f"-D {d}: expected NAME=VALUE")
        defines[name] = float(value)

    start = time.perf_counter()
    if args.scheduler:
        client, cluster = Client(args.scheduler), None
    else:
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, dashboard_address=None)
        client = Client(cluster)
    try:
        if args.scene:
            written = sylva_dask.frames(client, args.scene, args.frames, args.output, sylva=args.sylva)
        else:
            written = sylva_dask.batch(client, args.kind, args.grammar, args.seeds, args.output,
                                       defines=defines or None, mesh=args.mesh)
        workers = len(client.scheduler_info()["workers"])
    finally:
        client.close()
        if cluster:
            cluster.close()
    print(f"{len(written)} files from {workers} workers in {time.perf_counter() - start:.1f} s: "
          f"{written[0]} .. {written[-1]}")


if __name__ == "__main__":
    main()
