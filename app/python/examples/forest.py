#!/usr/bin/python3
"""forest.py — grow a forest of plants with varied seeds and write them as glTF binaries.

Each plant is written to OUT/<grammar>_<seed>.glb, and all of them together, placed on
a jittered grid with random turns, to OUT/forest.glb (one node per plant, each carrying
its skeleton in extras). Plants grow in a thread pool: Grammar.grow() and export_gltf()
release the GIL, so the threads run in parallel.

    PYTHONPATH=build-py/python /usr/bin/python3 app/python/examples/forest.py \
        --grammar presets/elm.lsys --count 100 --out forest/
"""
import argparse
import concurrent.futures
import math
import os
import pathlib
import random

import sylva


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grammar", default="presets/elm.lsys", help="the .lsys file to grow")
    parser.add_argument("--count", type=int, default=100, help="number of plants (default 100)")
    parser.add_argument("--first-seed", type=int, default=1, help="seed of the first plant; then +1 each")
    parser.add_argument("--spacing", type=float, default=12.0, help="grid spacing in metres")
    parser.add_argument("--mesh", action="store_true", help="also write the skinned mesh")
    parser.add_argument("--out", default="forest", help="output folder")
    args = parser.parse_args(argv)

    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    grammar = sylva.Grammar.from_file(args.grammar)
    stem = pathlib.Path(args.grammar).stem
    seeds = [args.first_seed + i for i in range(args.count)]

    def grow_and_write(seed):
        skeleton = grammar.grow(seed=seed)
        sylva.export_gltf(skeleton, out / f"{stem}_{seed}.glb", mesh=args.mesh)
        return skeleton

    with concurrent.futures.ThreadPoolExecutor(max_workers=os.cpu_count()) as pool:
        plants = list(pool.map(grow_and_write, seeds))

    # Place the plants on a square grid, jittered by up to a quarter of the spacing.
    side = math.ceil(math.sqrt(len(plants)))
    layout = random.Random(args.first_seed)
    positions = [((i % side + layout.uniform(-0.25, 0.25)) * args.spacing, 0.0,
                  (i // side + layout.uniform(-0.25, 0.25)) * args.spacing) for i in range(len(plants))]
    turns = [layout.uniform(0, 360) for _ in plants]
    sylva.export_gltf(plants, out / "forest.glb", mesh=args.mesh, names=[f"{stem}_{s}" for s in seeds],
                      positions=positions, rotate_y_deg=turns)
    segments = sum(p.segment_count for p in plants)
    print(f"{len(plants)} plants ({segments} segments) written to {out}/ and {out / 'forest.glb'}")


if __name__ == "__main__":
    main()
