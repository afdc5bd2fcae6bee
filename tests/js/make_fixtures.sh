#!/bin/bash
# The viewer tests' inputs, made by the skinmesh command under test:
#   make_fixtures.sh SKINMESH DATA_DIR OUT_DIR
# 1ubi's mesh with its atom table; the same mesh without one; 2k39 model 1 ->
# 3 as a morph of 5 frames with both sides' atom tables; its three models as
# a trajectory (t from 0 to 2); an embedded page of each, and a --no-embed
# page inside the morph's directory. The atom tables are those the commands
# write beside their outputs; their row counts are checked against the atoms
# skinmesh used.
set -euo pipefail
skinmesh=$1 data=$2 out=$3
rm -rf "$out" && mkdir -p "$out/plain"
"$skinmesh" --quiet mesh "$data/1ubi.pdb" -o "$out/1ubi.ply"
atoms=$("$skinmesh" --json info "$data/1ubi.pdb" | python3 -c 'import json,sys; print(json.load(sys.stdin)["atoms"])')
rows=$(($(wc -l < "$out/1ubi.atoms.tsv") - 1))
[ "$atoms" = "$rows" ] || { echo "1ubi: the atom table has $rows rows, skinmesh kept $atoms atoms" >&2; exit 1; }
cp "$out/1ubi.ply" "$out/plain/1ubi.ply"
"$skinmesh" --quiet morph "$data/2k39_3models.pdb" "$data/2k39_3models.pdb" --target-model 3 --frames 5 \
  --pairs matched --format ply -o "$out/morph"
for side in source target; do
  rows=$(($(wc -l < "$out/morph/${side}_atoms.tsv") - 1))
  balls=$(grep -vc "^#" "$out/morph/$side.xyzr")
  [ "$rows" = "$balls" ] || { echo "2k39 $side: $rows rows, $balls atoms in the morph" >&2; exit 1; }
done
"$skinmesh" --quiet trajectory "$data/2k39_3models.pdb" --frames-per-step 2 --format ply -o "$out/traj"
"$skinmesh" --quiet view "$out/1ubi.ply" -o "$out/1ubi.html"
"$skinmesh" --quiet view "$out/traj" -o "$out/traj.html"
"$skinmesh" --quiet view "$out/plain/1ubi.ply" -o "$out/plain/1ubi.html"
"$skinmesh" --quiet view "$out/morph" -o "$out/morph.html"
"$skinmesh" --quiet view "$out/morph" -o "$out/morph/index.html" --no-embed
