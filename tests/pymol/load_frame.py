"""PyMOL (Debian's python3-pymol, 2.5, headless) opens a frame that
`skinmesh morph --ascii` writes, with every vertex and triangle of it.

PyMOL 2.5 reads PLY as text only (pymol.cgo.from_plystr) into a CGO object
and has no reader for binary PLY, OBJ, STL, VTP or glTF. A CGO object
reports no vertex count of its own: it is exported as OBJ by PyMOL
(cmd.save), whose distinct vertex lines and face lines are counted against
the PLY header's. Usage: /usr/bin/python3 load_frame.py SKINMESH DATA_DIR
"""
import os
import subprocess
import sys
import tempfile

import pymol

pymol.finish_launching(["pymol", "-cq"])
from pymol import cmd  # noqa: E402 (after PyMOL is launched)


def ply_counts(path):
    """The vertex and face counts a PLY header announces, and its format line."""
    counts, form = {}, None
    with open(path, "rb") as f:
        for raw in f:
            line = raw.decode("ascii").split()
            if line[:1] == ["format"]:
                form = line[1]
            if line[:1] == ["element"]:
                counts[line[1]] = int(line[2])
            if line == ["end_header"]:
                break
    return counts["vertex"], counts["face"], form


def main(skinmesh, data):
    with tempfile.TemporaryDirectory() as work:
        out = os.path.join(work, "morph")
        pdb = os.path.join(data, "2k39_3models.pdb")
        subprocess.run([skinmesh, "--quiet", "morph", pdb, pdb, "--source-model", "1", "--target-model", "3",
                        "--frames", "3", "--format", "ply", "--ascii", "-o", out], check=True)
        frame = os.path.join(out, "frame_0001.ply")
        vertices, faces, form = ply_counts(frame)
        assert form == "ascii", form
        cmd.load(frame, "frame")
        assert cmd.get_names() == ["frame"], cmd.get_names()
        assert cmd.get_type("frame") == "object:cgo", cmd.get_type("frame")
        obj = os.path.join(work, "frame.obj")
        cmd.save(obj, "frame")
        with open(obj) as f:
            lines = f.read().splitlines()
        seen = len({l for l in lines if l.startswith("v ")})
        triangles = sum(1 for l in lines if l.startswith("f "))
        print(f"{frame}: {vertices} vertices, {faces} triangles in the file; PyMOL holds {seen} and {triangles}")
        assert (seen, triangles) == (vertices, faces)


if __name__ == "__main__":
    main(*sys.argv[1:3])
