#!/usr/bin/env python3
"""Mesh one structure with `skinmesh mesh` and record what happened.

    mesh_one.py SKINMESH STRUCTURE OUTDIR [-- MESH OPTIONS...]

Writes OUTDIR/status.json whatever the outcome: "ok" with the mesh, the
report, triangles, guarantees, seconds and the child's peak memory, or
"failed" with the exit code and the reason skinmesh gave. Exits 0 either
way, so that one structure's failure never stops a batch.
"""
import json
import os
import resource
import subprocess
import sys
import time


def main(argv):
    if len(argv) < 4:
        sys.stderr.write(__doc__)
        return 2
    skinmesh, structure, outdir = argv[1], argv[2], argv[3]
    extra = argv[5:] if len(argv) > 4 and argv[4] == "--" else argv[4:]
    os.makedirs(outdir, exist_ok=True)
    mesh = os.path.join(outdir, "mesh.ply")
    report = os.path.join(outdir, "report.json")
    command = [skinmesh, "--quiet", "mesh", structure, "-o", mesh, "--report", report] + extra
    start = time.monotonic()
    child = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    out, err = child.communicate()
    # This process runs one child: the children's peak resident memory is its own.
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    seconds = time.monotonic() - start
    code = child.returncode
    record = {"structure": structure, "command": command, "exit_code": code, "seconds": round(seconds, 3)}
    record["peak_mb"] = round(usage.ru_maxrss / 1024, 1)
    if code == 0:
        with open(report) as f:
            r = json.load(f)
        record.update(
            status="ok",
            mesh=os.path.basename(mesh),
            report=os.path.basename(report),
            atoms=r["atoms"],
            triangles=r["quality"]["triangles"],
            min_angle=r["quality"]["min_angle_deg"],
            guarantees=all(v is not False for v in r["guarantees"].values()),
            seconds_skinmesh=r["seconds"]["total"],
        )
    else:
        lines = [l for l in err.splitlines() if l.strip()]
        record.update(status="failed", reason=lines[-1] if lines else "exit code %d" % code)
    tmp = os.path.join(outdir, "status.json.tmp")
    with open(tmp, "w") as f:
        json.dump(record, f, indent=2)
        f.write("\n")
    os.replace(tmp, os.path.join(outdir, "status.json"))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
