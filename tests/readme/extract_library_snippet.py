#!/usr/bin/env python3
"""The README's library example as a project on disk.

    extract_library_snippet.py README OUT_DIR

Writes the ```cmake block under the heading "Using it as a library" as
OUT_DIR/CMakeLists.txt and the ```cpp block as OUT_DIR/skin.cpp, so that a
test builds them against the installed package exactly as the README shows
them. Exit 2 when the README has no such blocks.
"""
import os
import sys

HEADING = "Using it as a library"


def main():
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    with open(sys.argv[1], encoding="utf-8") as f:
        lines = f.read().splitlines()
    start = next((i for i, l in enumerate(lines) if l.startswith("#") and HEADING in l), None)
    if start is None:
        print("README: no heading '%s'" % HEADING, file=sys.stderr)
        return 2
    blocks, i = {}, start + 1
    while i < len(lines) and not lines[i].startswith("## "):
        if lines[i].startswith("```") and lines[i][3:].strip() in ("cmake", "cpp"):
            kind, body = lines[i][3:].strip(), []
            i += 1
            while i < len(lines) and not lines[i].startswith("```"):
                body.append(lines[i])
                i += 1
            blocks.setdefault(kind, body)
        i += 1
    if set(blocks) != {"cmake", "cpp"}:
        print("README: '%s' needs a ```cmake and a ```cpp block" % HEADING, file=sys.stderr)
        return 2
    os.makedirs(sys.argv[2], exist_ok=True)
    for kind, name in (("cmake", "CMakeLists.txt"), ("cpp", "skin.cpp")):
        with open(os.path.join(sys.argv[2], name), "w", encoding="utf-8") as f:
            f.write("\n".join(blocks[kind]) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
