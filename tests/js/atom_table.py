#!/usr/bin/env python3
"""Writes an atom table (the TSV `skinmesh view` reads) from a PDB file, for
the viewer's test fixtures: one row per atom skinmesh keeps by default (first
or chosen model, heavy atoms, no waters, the first alternate location), in
file order, so that row `index` is the per-vertex atom value.

    atom_table.py FILE.pdb OUT.tsv [--model N]
"""
import sys

RADII = {"C": 1.70, "N": 1.55, "O": 1.52, "S": 1.80, "P": 1.80, "H": 1.20}  # Bondi
WATERS = {"HOH", "WAT", "DOD", "H2O"}


def atoms(path, model):
    current, chosen = 1, {}
    for line in open(path, encoding="utf-8", errors="replace"):
        if line.startswith("MODEL"):
            current = int(line[10:14])
        if current != model or not line.startswith(("ATOM  ", "HETATM")):
            continue
        element = (line[76:78].strip() or line[12:14].strip()).capitalize()
        residue = line[17:20].strip()
        if element in ("H", "D") or residue in WATERS:
            continue
        key = (line[21], line[22:26].strip(), line[26].strip())
        altloc = line[16].strip()
        if altloc and chosen.setdefault(key, altloc) != altloc:
            continue
        yield [line[21].strip(), line[22:26].strip(), line[26].strip(), residue, line[12:16].strip(), element,
               "%.2f" % RADII.get(element, 1.80)]


def main():
    model = int(sys.argv[sys.argv.index("--model") + 1]) if "--model" in sys.argv else 1
    rows = list(atoms(sys.argv[1], model))
    with open(sys.argv[2], "w", encoding="utf-8") as out:
        out.write("index\tchain\tresidue_number\tinsertion_code\tresidue_name\tatom_name\telement\tradius\n")
        for k, row in enumerate(rows):
            out.write("\t".join([str(k)] + row) + "\n")


if __name__ == "__main__":
    main()
