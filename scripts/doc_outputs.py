#!/usr/bin/env python3
"""What the docs show a command printing is what it prints.

    doc_outputs.py check|update BUILD_DIR FILE...

A block of printed output in a doc is marked by the line before it:

    <!-- output: COMMAND ; COMMAND ; ... -->
    ```
    ...what the commands print on stdout, in order...
    ```

or, for a Markdown table the commands print, by the line before the table
(the block then runs to the next blank line).

The commands run one after another in a temporary directory, with
`./build/` standing for BUILD_DIR, `scripts/` and `data/` for the
repository's
(and the data directory's absolute path written back as `data/` in what
they print). `check` compares every marked block with the output, except
the numbers on lines holding `time:`, and exits 1 with a diff when one
differs; `update` rewrites the blocks. Exit 2 on a malformed marker.
"""
import difflib
import os
import re
import shlex
import subprocess
import sys
import tempfile

MARKER = re.compile(r"^<!-- output: (.*) -->$")
NUMBER = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.path.join(ROOT, "data")


def comparable(line):
    return NUMBER.sub("N", line) if "time:" in line else line


def marked_blocks(lines, path):
    """(commands, first body line, end line) of every marked block."""
    found = []
    for i, line in enumerate(lines):
        m = MARKER.match(line.strip())
        if not m:
            continue
        commands = [c.strip() for c in m.group(1).split(" ; ")]
        if i + 1 < len(lines) and lines[i + 1].startswith("|"):  # a table, to the next blank line
            end = next((j for j in range(i + 1, len(lines)) if not lines[j].strip()), len(lines))
            found.append((commands, i + 1, end))
            continue
        if i + 1 >= len(lines) or not lines[i + 1].startswith("```"):
            sys.exit("%s:%d: an output marker must be followed by a fenced block or a table" % (path, i + 1))
        end = next((j for j in range(i + 2, len(lines)) if lines[j].startswith("```")), None)
        if end is None:
            sys.exit("%s:%d: the fenced block is not closed" % (path, i + 2))
        found.append((commands, i + 2, end))
    return found


def run(commands, build_dir):
    printed = []
    with tempfile.TemporaryDirectory() as work:
        for command in commands:
            words = shlex.split(command)
            words = [os.path.join(build_dir, w[len("./build/"):]) if w.startswith("./build/") else
                     os.path.join(ROOT, w) if w.startswith(("data/", "scripts/")) else w for w in words]
            done = subprocess.run(words, cwd=work, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            if done.returncode != 0:
                raise RuntimeError("%s: exit %d\n%s" % (command, done.returncode, done.stderr))
            printed += done.stdout.replace(DATA + "/", "data/").splitlines()
    return printed


def main():
    if len(sys.argv) < 4 or sys.argv[1] not in ("check", "update"):
        print(__doc__, file=sys.stderr)
        return 2
    mode, build_dir, files = sys.argv[1], os.path.abspath(sys.argv[2]), sys.argv[3:]
    differ = 0
    for path in files:
        with open(path, encoding="utf-8") as f:
            lines = f.read().splitlines()
        blocks = marked_blocks(lines, path)
        for commands, start, end in reversed(blocks):  # from the end: updates keep earlier indices
            shown, printed = lines[start:end], run(commands, build_dir)
            if [comparable(l) for l in shown] == [comparable(l) for l in printed]:
                continue
            if mode == "update":
                lines[start:end] = printed
                continue
            differ += 1
            print("%s:%d: the block differs from what %s prints (numbers on time: lines not compared):"
                  % (path, start, " ; ".join(commands)))
            sys.stdout.writelines(difflib.unified_diff([l + "\n" for l in shown], [l + "\n" for l in printed],
                                                       path, "printed"))
        if mode == "update":
            with open(path, "w", encoding="utf-8") as f:
                f.write("\n".join(lines) + "\n")
        print("%s: %d marked block(s)" % (path, len(blocks)))
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
