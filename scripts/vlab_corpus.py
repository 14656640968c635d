#!/usr/bin/env python3
"""Grows every cpfg object of a vlab object tree with sylva and says which grow.

Issue 30's measure: "at least nine in ten of vlab's cpfg example objects grow unchanged".
vlab's objects are not bundled with sylva (they are vlab's); point this at a checkout:

    git clone https://github.com/AlgorithmicBotany/vlab
    scripts/vlab_corpus.py --sylva build/release/app/sylva vlab/oofs [--markdown out.md]

An object is a folder with a `specifications` file whose menu runs `cpfg` (lpfg objects
are another program's and are not counted). Each is grown with `sylva grow OBJECT -o ...`
under a time limit; an object grows when sylva exits 0 and writes a skeleton with at
least one segment or leaf. The others are listed with the first line of sylva's error,
so the table says what is still missing and where.
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time

CPFG_LINE = re.compile(r"^\s*cpfg\b")


def cpfg_objects(root):
    found = []
    for folder, _dirs, files in os.walk(root):
        if "specifications" not in files:
            continue
        try:
            with open(os.path.join(folder, "specifications"), errors="replace") as f:
                if any(CPFG_LINE.match(line) for line in f):
                    found.append(folder)
        except OSError:
            continue
    return sorted(found)


def first_error(text):
    for line in text.splitlines():
        if "error:" in line:
            return line.strip()
    lines = [l.strip() for l in text.splitlines() if l.strip()]
    return lines[0] if lines else "(no message)"


def grow(sylva, folder, timeout, out_dir):
    out = os.path.join(out_dir, "plant.skel.json")
    if os.path.exists(out):
        os.remove(out)
    start = time.monotonic()
    try:
        run = subprocess.run([sylva, "grow", folder, "-o", out], capture_output=True,
                             text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return False, f"timed out after {timeout} s", timeout
    seconds = time.monotonic() - start
    if run.returncode != 0:
        return False, first_error(run.stderr + run.stdout), seconds
    try:
        with open(out) as f:
            skel = json.load(f)
    except (OSError, ValueError) as e:
        return False, f"no readable skeleton: {e}", seconds
    parts = sum(len(c.get("joints", [])) for c in skel.get("chains", [])) + \
        len(skel.get("leaves", []))
    if parts == 0:
        return False, "an empty skeleton", seconds
    return True, run.stdout.strip().splitlines()[-1] if run.stdout.strip() else "", seconds


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("root", help="a vlab object tree (vlab's oofs folder)")
    ap.add_argument("--sylva", default="build/release/app/sylva")
    ap.add_argument("--timeout", type=float, default=120.0)
    ap.add_argument("--markdown", help="write the table here as well")
    args = ap.parse_args()

    objects = cpfg_objects(args.root)
    if not objects:
        sys.exit(f"{args.root}: no cpfg objects (folders whose specifications run cpfg)")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for folder in objects:
            ok, what, seconds = grow(args.sylva, folder, args.timeout, tmp)
            name = os.path.relpath(folder, args.root)
            rows.append((name, ok, what, seconds))
            print(f"{'grows' if ok else 'FAILS'}  {seconds:6.2f} s  {name}: {what}", flush=True)
    grown = sum(1 for r in rows if r[1])
    summary = f"{grown} of {len(rows)} cpfg objects grow ({100.0 * grown / len(rows):.0f} %)"
    print(summary)
    if args.markdown:
        with open(args.markdown, "w") as f:
            f.write(f"{summary}\n\n| object | grows | s | sylva says |\n|---|---|---|---|\n")
            for name, ok, what, seconds in rows:
                f.write(f"| {name} | {'yes' if ok else 'no'} | {seconds:.2f} | "
                        f"{what.replace('|', '/')} |\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
