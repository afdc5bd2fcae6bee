#!/usr/bin/env python3
"""A Markdown table of morph directories, from their morph.json and frames.jsonl.

    morph_table.py DIR...

One row per directory: the pairing, the frames, those remeshed whole and
meshed from scratch, the least share of ids kept a frame (moving atoms),
the smallest angle and the largest distance from the skin over every
frame, and the triangles of the frame nearest t = 1/2. Used by the docs'
marked blocks (scripts/doc_outputs.py), so that the table is what a run
gives.
"""
import json
import os
import sys


def row(directory):
    with open(os.path.join(directory, "morph.json"), encoding="utf-8") as f:
        report = json.load(f)
    with open(os.path.join(directory, "frames.jsonl"), encoding="utf-8") as f:
        frames = [json.loads(line) for line in f if line.strip()]
    middle = min(frames, key=lambda fr: abs(fr["t"] - 0.5))
    later = frames[1:]
    ids = "%.2f" % min(fr["ids_kept"] for fr in later) if later and "ids_kept" in later[0] else "(not kept)"
    return "| `%s` | %d | %d | %d | %s | %.2f | %.1e | %s (t = %.2f) |" % (
        report["pairs"], len(frames), sum(bool(fr.get("remeshed")) for fr in later),
        sum(bool(fr.get("full_rebuild")) for fr in frames), ids, min(fr["min_angle"] for fr in frames),
        max(fr["max_onsurf_error"] for fr in frames), "{:,}".format(middle["triangles"]), middle["t"])


def main():
    if len(sys.argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    print("| `--pairs` | frames | remeshed whole | meshed from scratch | ids kept, least a frame | "
          "smallest angle | largest error A | triangles at t = 1/2 |")
    print("|---|---|---|---|---|---|---|---|")
    for directory in sys.argv[1:]:
        print(row(directory))
    return 0


if __name__ == "__main__":
    sys.exit(main())
