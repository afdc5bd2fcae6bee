#!/usr/bin/env python3
"""Writes this folder's hostile inputs (issue 39, round two) from data/pept.pdb.

Run from anywhere: python3 tests/hostile/make_inputs.py. The files are kept
in git; this script says how each was made. The jitter is seeded, so a rerun
writes the same bytes.
"""
import os
import random

here = os.path.dirname(os.path.abspath(__file__))
pept = os.path.join(here, "..", "..", "data", "pept.pdb")
atoms = [line.rstrip("\n") for line in open(pept) if line.startswith(("ATOM", "HETATM"))]
# Bondi radii of pept's elements (as skinmesh's table gives them).
radius = {"C": 1.70, "N": 1.55, "O": 1.52, "S": 1.80}


def fields(line):
    return {"serial": int(line[6:11]), "name": line[12:16].strip(), "res": line[17:20].strip(),
            "chain": line[21], "seq": int(line[22:26]), "x": float(line[30:38]), "y": float(line[38:46]),
            "z": float(line[46:54]), "element": line[76:78].strip()}


def write(name, text, bom=False):
    with open(os.path.join(here, name), "wb") as out:
        out.write((b"\xef\xbb\xbf" if bom else b"") + text.encode())


def pqr(records, decimals=7):
    return "".join(f"ATOM  {a['serial']:5d} {a['name']:<4} {a['res']} {a['chain']} {a['seq']:3d}    "
                   f"{a['x']:.{decimals}f} {a['y']:.{decimals}f} {a['z']:.{decimals}f} 0.0000 "
                   f"{radius[a['element']]:.4f}\n" for a in records)


def mmcif(records):
    head = ("data_pept_jittered\nloop_\n" + "".join(f"_atom_site.{c}\n" for c in (
        "group_PDB", "id", "type_symbol", "label_atom_id", "label_alt_id", "label_comp_id", "label_asym_id",
        "label_entity_id", "label_seq_id",
        "Cartn_x", "Cartn_y", "Cartn_z", "occupancy", "B_iso_or_equiv", "auth_seq_id", "auth_comp_id",
        "auth_asym_id", "auth_atom_id", "pdbx_PDB_model_num")))
    return head + "".join(f"ATOM {a['serial']} {a['element']} {a['name']} . {a['res']} {a['chain']} 1 {a['seq']} "
                          f"{a['x']:.7f} {a['y']:.7f} {a['z']:.7f} 1.00 0.00 {a['seq']} {a['res']} {a['chain']} "
                          f"{a['name']} 1\n" for a in records)


records = [fields(line) for line in atoms]
pdb_text = "".join(line + "\n" for line in atoms) + "END\n"

# A UTF-8 byte-order mark before the first record, in PDB and PQR.
write("pept-bom.pdb", pdb_text, bom=True)
write("pept-bom.pqr", pqr(records), bom=True)
# One atom's record twice (the copy with the next serial number), last.
copy = atoms[49][:6] + f"{len(atoms) + 1:5d}" + atoms[49][11:]
write("pept-duplicate.pdb", "".join(line + "\n" for line in atoms) + copy + "\nEND\n")
# Every coordinate moved by up to 1e-6 A (uniform, seeded): PQR and mmCIF
# keep seven decimals, PDB's three would round the jitter away.
random.seed(39)
jittered = [dict(a, x=a["x"] + random.uniform(-1e-6, 1e-6), y=a["y"] + random.uniform(-1e-6, 1e-6),
                 z=a["z"] + random.uniform(-1e-6, 1e-6)) for a in records]
write("pept-jitter.pqr", pqr(jittered))
write("pept-jitter.cif", mmcif(jittered))
# The same at 1e-9 A (twelve decimals) and at 3e-5 A, both inside the 5e-4 A
# within which a morph or interpolate takes an atom as unmoved.
for size, name, decimals in ((1e-9, "pept-jitter-1e-9.pqr", 12), (3e-5, "pept-jitter-3e-5.pqr", 7)):
    random.seed(39)
    write(name, pqr([dict(a, x=a["x"] + random.uniform(-size, size), y=a["y"] + random.uniform(-size, size),
                          z=a["z"] + random.uniform(-size, size)) for a in records], decimals))
# One atom, and the same atom twice.
write("one-atom.xyzr", "0 0 0 1.7\n")
write("one-atom-twice.xyzr", "0 0 0 1.7\n0 0 0 1.7\n")
# Weighted points of negative weight only: an empty skin.
write("all-negative.wpts", "# x y z weight\n0 0 0 -1\n1 0 0 -2\n0 1 0 -0.5\n")
