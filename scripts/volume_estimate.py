#!/usr/bin/env python3
"""How close `skinmesh volume`'s estimate of TetGen's tetrahedra comes.

    python3 scripts/volume_estimate.py [SKINMESH]

Runs `volume` on molecules of data/ at several domains, box margins and
bounds (one at a time, from the repository's root), and prints a Markdown
table: the estimate and its low end (the report's `estimated_tetrahedra`),
the tetrahedra TetGen made, their ratio to the estimate, and the run's peak
memory (the largest resident set of the command and its TetGen child). The
table in docs/volume-meshes.md ("Knowing the size before running") is its
output. Takes a few minutes.
"""
import json
import os
import resource
import subprocess
import sys
import tempfile

RUNS = [
    ("pept", []),
    ("pept", ["--max-radius-edge", "1.5"]),
    ("pept", ["--max-radius-edge", "10", "--min-dihedral", "0"]),
    ("pept", ["--min-dihedral", "11", "--max-radius-edge", "1.5"]),
    ("pept", ["--min-dihedral", "12", "--max-radius-edge", "1.2"]),
    ("pept", ["--min-dihedral", "14", "--max-radius-edge", "1.5"]),
    ("pept", ["--max-volume", "0.02"]),
    ("pept", ["--domain", "exterior", "--box-margin", "5"]),
    ("pept", ["--domain", "exterior", "--box-margin", "40"]),
    ("pept", ["--domain", "exterior", "--box-margin", "160"]),
    ("pept", ["--domain", "exterior", "--max-volume", "1"]),
    ("pept", ["--domain", "both"]),
    ("3al1", []),
    ("3al1", ["--domain", "exterior", "--box-margin", "40"]),
    ("3al1", ["--domain", "exterior", "--min-dihedral", "12", "--max-radius-edge", "1.2"]),
    ("1ubi", []),
    ("1ubi", ["--domain", "exterior", "--box-margin", "30"]),
]


def run(skinmesh, molecule, options, folder):
    command = [skinmesh, "--json", "volume", f"data/{molecule}.pdb", "-o", os.path.join(folder, "v")] + options
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
    out = process.stdout.read()
    _, status, usage = os.wait4(process.pid, 0)
    if status != 0:
        return None, usage.ru_maxrss
    return json.loads(out), usage.ru_maxrss


def main():
    skinmesh = sys.argv[1] if len(sys.argv) > 1 else "./build/app/skinmesh"
    print("| molecule | options | estimate (low end) | TetGen's | ratio | peak MB |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as folder:
        for molecule, options in RUNS:
            report, peak_kb = run(skinmesh, molecule, options, folder)
            shown = " ".join(options) or "(defaults)"
            if report is None:
                print(f"| {molecule} | `{shown}` | failed | | | |")
                continue
            expected = report["estimated_tetrahedra"]["expected"]
            low = report["estimated_tetrahedra"]["low"]
            made = report["tetrahedra"]
            print(f"| {molecule} | `{shown}` | {expected} ({low}) | {made} | {made / expected:.2f} | "
                  f"{peak_kb / 1024:.0f} |", flush=True)


if __name__ == "__main__":
    main()
