#!/usr/bin/env bash
# The batch workflow (workflows/Snakefile, docs/batch.md) on data/ with one
# broken structure and one missing file: every good structure meshed, the
# two failures recorded with their reason and skipped, a summary row each;
# a second run does nothing.
#     test_workflow.sh SKINMESH DATA_DIR WORKFLOW_DIR
set -euo pipefail
skinmesh=$1 data=$2 workflows=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
printf 'ATOM      1  CA  ALA A   1      1.000   2.000   x.000  1.00  0.00           C\n' > "$work/broken.pdb"
{
  echo "# three structures of data/, one broken, one missing"
  echo "$data/pept.pdb"
  echo "$data/1ubi.pdb"
  echo "$data/3al1.pdb"
  echo "$work/broken.pdb"
  echo "$work/missing.pdb"
} > "$work/list.txt"
run() {
  snakemake -s "$workflows/Snakefile" --cores 2 -d "$work" --config list="$work/list.txt" out="$work/meshes" \
    skinmesh="$skinmesh" 2>&1
}
first=$(run)
summary="$work/meshes/summary.tsv"
[ -f "$summary" ] || { echo "no summary"; echo "$first"; exit 1; }
cat "$summary"
[ "$(tail -n +2 "$summary" | wc -l)" -eq 5 ] || { echo "expected 5 rows"; exit 1; }
[ "$(grep -c $'\tok\t' "$summary")" -eq 3 ] || { echo "expected 3 structures ok"; exit 1; }
grep $'\tfailed\t' "$summary" | grep -q "broken.pdb:1" || { echo "the broken file's failure names it and its line"; exit 1; }
grep $'\tfailed\t' "$summary" | grep -q "missing.pdb" || { echo "the missing file's failure names it"; exit 1; }
[ -f "$work/meshes/1ubi/mesh.ply" ] || { echo "no mesh for 1ubi"; exit 1; }
second=$(run)
echo "$second" | grep -q "Nothing to be done" || { echo "the second run redid work:"; echo "$second"; exit 1; }
echo "1 passed, 0 failed"
