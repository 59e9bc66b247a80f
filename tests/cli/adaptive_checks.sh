#!/usr/bin/env bash
# adaptive_checks.sh CASE TERRALUX CHECKER WORKDIR DEM
# End-to-end cases of adaptive probe volumes that need more than one command.
set -u
case_=$1 terralux=$2 checker=$3 work=$4 dem=$5
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*"; exit 1; }
adaptive=(--set 'probe_volumes[0].placement=adaptive' --set 'probe_volumes[0].name=valley')
case "$case_" in
  dry_run)
    # Estimates only: exit 0, a line per volume, and no output folder.
    "$terralux" --bake --dry-run --dem "$dem" --out "$work/out" "${adaptive[@]}" \
      --set 'probe_volumes[0].adaptive.tolerance=0.03' >"$work/stdout" 2>"$work/stderr" || fail "dry run exited $?"
    grep -q "^dry run: nothing baked, nothing written" "$work/stdout" || fail "no dry-run header"
    grep -Eq "^  valley: adaptive, cells 30.00 to 480.00 m, 95 x 38 x 63 cells of 30.00 m: [0-9]+ probes .*, [0-9]+ bytes, [0-9]+ error-map points, about" "$work/stdout" || fail "no volume estimate"
    grep -Eq "error-driven refinement to 3.00 %: up to [0-9]+ probes" "$work/stdout" || fail "no refinement estimate"
    grep -Eq "^estimated bake time: about" "$work/stdout" || fail "no total"
    [ -e "$work/out" ] && fail "the dry run created $work/out"
    [ -s "$work/stderr" ] && fail "stderr not empty"
    ;;
  threads)
    # The same project bakes to the same bytes with 1 and 2 threads; the files agree with the
    # glTF and the report, which states what placement did.
    for t in 1 2; do
      "$terralux" --bake --quiet --quality draft --dem "$dem" --out "$work/t$t" --threads $t "${adaptive[@]}" \
        --set 'probe_volumes[0].adaptive.tolerance=0.04' --set 'probe_volumes[0].adaptive.min_cell_size=60' \
        --set 'probe_volumes[0].adaptive.max_cell_size=960' >/dev/null || fail "bake with $t thread(s) exited $?"
    done
    cmp "$work/t1/sh_coeffs/valley.shprobe" "$work/t2/sh_coeffs/valley.shprobe" || fail ".shprobe differs"
    cmp "$work/t1/sh_coeffs/valley.probes.json" "$work/t2/sh_coeffs/valley.probes.json" || fail "probes.json differs"
    "$checker" "$work/t1" || fail "glTF entries disagree with the .shprobe headers"
    for key in '"moved_probes"' '"split_for_inside"' '"borrowed_cells"' '"interpolation_error"' \
               '"probes_with_rays_from_below": 0' '"overlaps": \[\]' '"tolerance": 0.04'; do
      grep -q "$key" "$work/t1/bake_report.json" || fail "bake_report.json lacks $key"
    done
    ;;
  real)
    [ -f "$dem" ] || { echo "SKIP: shared DEM not present: $dem"; exit 77; }
    "$terralux" --bake --quiet --quality draft --dem "$dem" --out "$work/out" "${adaptive[@]}" \
      --set terrain.max_resolution=300 --set 'probe_volumes[0].adaptive.max_move_share=0.5' \
      >/dev/null || fail "bake exited $?"
    "$checker" "$work/out" || fail "glTF entries disagree with the .shprobe headers"
    grep -q '"probes_with_rays_from_below": 0' "$work/out/bake_report.json" || fail "a probe sees the terrain from below"
    ;;
  *) echo "unknown case $case_"; exit 2 ;;
esac
echo "ok: $case_"
