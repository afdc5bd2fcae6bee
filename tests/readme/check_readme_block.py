#!/usr/bin/env python3
"""The README's main job prints what the README shows.

    check_readme_block.py SKINMESH README DATA_DIR

Takes the main job from the README's first ```sh block (the line with
`&& `: what follows `&& ` up to `#`), runs it in a temporary directory with
./build/app/skinmesh replaced by SKINMESH and data/ by DATA_DIR, and compares
its standard output line by line with the first fenced block under the
heading "What the main job prints". Only the numbers on the `time:` line are
not compared. Exit 0 when they agree; otherwise 1 with a diff (2 when the
README cannot be parsed).
"""
import difflib
import os
import re
import shlex
import subprocess
import sys
import tempfile

HEADING = "What the main job prints"
NUMBER = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")


def fail(message):
    print("README: " + message, file=sys.stderr)
    sys.exit(2)


def fenced_blocks(lines):
    """(info string, body lines, index of the opening fence) of every fenced block."""
    blocks, i = [], 0
    while i < len(lines):
        if lines[i].startswith("```"):
            info, start, i = lines[i][3:].strip(), i, i + 1
            body = []
            while i < len(lines) and not lines[i].startswith("```"):
                body.append(lines[i])
                i += 1
            blocks.append((info, body, start))
        i += 1
    return blocks


def main_job(blocks, binary, data_dir):
    sh = next((body for info, body, _ in blocks if info == "sh"), None)
    if sh is None:
        fail("no ```sh block")
    line = next((l for l in sh if "&& " in l), None)
    if line is None:
        fail("the first ```sh block has no line with '&& '")
    words = shlex.split(line.split("&& ", 1)[1].split("#", 1)[0])
    if not words or words[0] != "./build/app/skinmesh":
        fail("the main job does not start with ./build/app/skinmesh: %r" % line)
    words[0] = binary
    return [os.path.join(data_dir, w[len("data/"):]) if w.startswith("data/") else w for w in words]


def printed_block(lines, blocks):
    heading = next((i for i, l in enumerate(lines) if l.startswith("#") and HEADING in l), None)
    if heading is None:
        fail("no heading '%s'" % HEADING)
    block = next((body for _, body, start in blocks if start > heading), None)
    if block is None:
        fail("no fenced block under '%s'" % HEADING)
    return block


def comparable(line):
    return NUMBER.sub("N", line) if line.strip().startswith("time:") else line


def main():
    if len(sys.argv) != 4:
        print(__doc__, file=sys.stderr)
        return 2
    binary, readme, data_dir = os.path.abspath(sys.argv[1]), sys.argv[2], os.path.abspath(sys.argv[3])
    with open(readme, encoding="utf-8") as f:
        lines = f.read().splitlines()
    blocks = fenced_blocks(lines)
    command = main_job(blocks, binary, data_dir)
    expected = printed_block(lines, blocks)
    with tempfile.TemporaryDirectory() as work:
        run = subprocess.run(command, cwd=work, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    print("ran:", " ".join(shlex.quote(w) for w in command))
    if run.returncode != 0:
        print("exit code %d; stderr:\n%s" % (run.returncode, run.stderr))
        return 1
    printed = run.stdout.splitlines()
    if [comparable(l) for l in printed] == [comparable(l) for l in expected]:
        print("the README's block is what the main job prints (%d lines)" % len(printed))
        return 0
    # In the diff a time line that agrees but for its numbers is shown as the README's.
    same_but_numbers = {comparable(l): l for l in expected if l.strip().startswith("time:")}
    shown = [same_but_numbers.get(comparable(l), l) if l.strip().startswith("time:") else l for l in printed]
    print("the main job's output differs from the README's block (the time line's numbers are not compared):")
    sys.stdout.writelines(difflib.unified_diff([l + "\n" for l in expected], [l + "\n" for l in shown],
                                               "README.md", "printed"))
    return 1


if __name__ == "__main__":
    sys.exit(main())
