#!/usr/bin/env bash
# plinth-sweep run as a user would (docs/sweep.md): shards merged equal the whole run byte for
# byte, an interrupted run keeps its rows and a rerun resumes to the same file, the ground's
# columns of --compare-ground are a run of the block on the ground, plots are written (or a
# missing gnuplot is named), and bad inputs end with exit code 1 or 2 and a message naming
# the problem. Prints "ok - <name>" or "not ok - <name>: <why>" per check,
# then "N passed, M failed".
#
# Environment: PLINTH_SWEEP, the plinth-sweep binary; PLINTH_SOURCE_DIR, the repository root.
set -u

PLINTH_SIM=${PLINTH_SWEEP:-}
# shellcheck source=tests/cli/harness.sh
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"
SWEEP=$SIM
ISOLATED=$SCENES/paper-isolated.toml

# sweep ARGS...: plinth-sweep ARGS with stdout in $TMP/out.txt, stderr in $TMP/err.txt and
# the exit code in RC.
sweep() {
  RC=0
  "${TIMEOUT[@]}" "$SWEEP" "$@" >"$TMP/out.txt" 2>"$TMP/err.txt" || RC=$?
}

# check NAME CONDITION...: passes when the command CONDITION succeeds.
check() {
  local name=$1
  shift
  if "$@"; then pass "$name"; else fail "$name" "$(head -c 300 "$TMP/err.txt")"; fi
}

# refuses NAME PATTERN ARGS...: plinth-sweep ARGS must exit with 1 or 2 and say PATTERN
# (extended regex) on stderr.
refuses() {
  local name=$1 pattern=$2
  shift 2
  sweep "$@"
  if ((RC != 1 && RC != 2)); then
    fail "$name" "exit code $RC, expected 1 or 2; stderr: $(head -c 200 "$TMP/err.txt")"
  elif ! grep -Eq -- "$pattern" "$TMP/err.txt"; then
    fail "$name" "stderr does not match '$pattern': $(head -c 200 "$TMP/err.txt")"
  else
    pass "$name"
  fi
}

# A small but real sweep: 4 values of mu_s, coarse search.
SMALL=(--scene "$ISOLATED" --record "$AT2" --param mu_s --from 0.2 --to 0.5 --steps 4
       --pga-max 4g --tol 0.05g --dt 4e-3)

sweep "${SMALL[@]}" --jobs 2 --out whole.csv
check "a sweep writes its map" test "$RC" -eq 0 -a -s whole.csv
check "the first line records the settings" \
  grep -q '^# plinth-sweep thresholds grid=mu_s:0.2:0.5:4 scene=' whole.csv
check "the header names the parameter and the events" grep -qx \
  'mu_s,sliding,rocking,slide_rocking,out_of_base,base_stop_hit,slide_stop_hit,fell,overturned,lift_off' whole.csv
check "one row per value" test "$(grep -c '^0\.' whole.csv)" -eq 4
check "no progress bar when stderr is not a terminal" test ! -s "$TMP/err.txt"

# Shards on their own, then merged: the same bytes as the whole run.
sweep "${SMALL[@]}" --jobs 1 --shard 2/3 --out part2.csv
sweep "${SMALL[@]}" --jobs 1 --shard 1/3 --out part1.csv
sweep "${SMALL[@]}" --jobs 1 --shard 3/3 --out part3.csv
sweep merge --out merged.csv part3.csv part1.csv part2.csv
check "shards merged equal the whole run byte for byte" cmp -s merged.csv whole.csv
refuses "merge refuses a missing shard" "1 of 4 rows are missing" merge --out m.csv part1.csv part2.csv
refuses "merge refuses a shard given twice" "is in both part1.csv and part1.csv" \
  merge --out m.csv part1.csv part1.csv part2.csv part3.csv
sweep --scene "$ISOLATED" --record "$AT2" --param mu_s --from 0.2 --to 0.5 --steps 4 \
  --pga-max 4g --tol 0.1g --dt 4e-3 --shard 3/3 --out other.csv
refuses "merge refuses shards of different sweeps" "come from different sweeps" \
  merge --out m.csv part1.csv part2.csv other.csv
printf 'mu_s,sliding\n0.2,1\n' >plain.csv
refuses "merge refuses a CSV without the settings line" "plain.csv.*not a plinth-sweep CSV" \
  merge --out m.csv plain.csv
refuses "merge of a file that is not there" "nothere.csv: cannot open" merge --out m.csv nothere.csv
refuses "a shard's file is not resumed by another shard" "holds row '0.2' of another shard" \
  "${SMALL[@]}" --shard 2/3 --out part1.csv

# Rerunning a finished sweep runs nothing and rewrites the same file.
cp whole.csv again.csv
sweep "${SMALL[@]}" --out again.csv
check "a finished sweep is resumed, not rerun" grep -q '4 resumed from again.csv), 0 simulations' "$TMP/out.txt"
check "and its file is unchanged" cmp -s again.csv whole.csv

# A finished file that differs only in line endings or formatting is resumed, and rewritten as
# plinth-sweep writes it (issue 25). The class walked: CRLF, classic Mac CR, a byte order mark,
# a spreadsheet's save (every field quoted, spaces after commas, the settings line padded with
# empty fields, numbers as 2.000000000E-01), blank lines and no final line feed.
declare -A RESAVED=(
  [crlf]="sed 's/\$/\r/'"
  [cr]="tr '\n' '\r'"
  [bom]="sed '1s/^/\xef\xbb\xbf/'"
  [spreadsheet]="awk 'NR == 1 { printf \"\\\"%s\\\",,,,,,,,,\r\n\", \$0; next }
    { n = split(\$0, f, \",\"); out = \"\"
      for (i = 1; i <= n; i++) { v = f[i]; if (v ~ /^[0-9.]+\$/) v = sprintf(\"%.9E\", v)
        out = out (i > 1 ? \", \" : \"\") \"\\\"\" v \"\\\"\" }
      printf \"%s\r\n\", out }'"
  [blank-lines]="awk '{ print } NR == 3 { print \"\"; print \",,,\" }' | head -c -1"
)
for variant in "${!RESAVED[@]}"; do
  eval "${RESAVED[$variant]}" <whole.csv >"resaved-$variant.csv"
  if cmp -s "resaved-$variant.csv" whole.csv; then
    fail "a file resaved ($variant) is resumed" "the variant changed nothing"
    continue
  fi
  sweep "${SMALL[@]}" --out "resaved-$variant.csv"
  check "a file resaved ($variant) is resumed" \
    grep -q "4 resumed from resaved-$variant.csv), 0 simulations" "$TMP/out.txt"
  check "and rewritten as plinth-sweep writes it ($variant)" cmp -s "resaved-$variant.csv" whole.csv
done
# A file that cannot be continued says why and keeps its rows beside (never replaced unseen).
sed 's/tol_g=0.05/tol_g=0.1/' whole.csv >othertol.csv
cp othertol.csv othertol.orig
sweep "${SMALL[@]}" --out othertol.csv
check "a file of another sweep says why it is not resumed" \
  grep -q "othertol.csv comes from another sweep (tol_g: 0.1 in the file, 0.05 in this run); not resumed: its 4 row(s) are kept as othertol.csv.kept" "$TMP/err.txt"
check "and its rows are kept" cmp -s othertol.csv.kept othertol.orig
check "and the run writes its own" cmp -s othertol.csv whole.csv
cp othertol.orig othertol.csv
sweep "${SMALL[@]}" --out othertol.csv
check "a second one is kept beside the first" cmp -s othertol.csv.kept-2 othertol.orig
printf 'not a sweep\n' >notsweep.csv
sweep "${SMALL[@]}" --out notsweep.csv
check "a file that is not a sweep CSV says so and is kept" \
  grep -q "notsweep.csv:1: not a plinth-sweep CSV.*not resumed: it is kept as notsweep.csv.kept" "$TMP/err.txt"
check "unchanged" grep -qx 'not a sweep' notsweep.csv.kept
# A file an older plinth-sweep wrote, before the lift_off column (whole.csv without it): not
# resumed, its version named; its own shards merge; a shard of it and one of this version do
# not, the older named; it plots without that column's curve, saying why (below, with gnuplot).
awk 'NR == 1 { print; next } { sub(/,[^,]*$/, ""); print }' whole.csv >older.csv
cp older.csv olderrun.csv
sweep "${SMALL[@]}" --out olderrun.csv
check "an older plinth-sweep's file is not resumed, its version named" \
  grep -q "olderrun.csv was written by a plinth-sweep older than its lift_off column (plinth 0.1.0 from commit 4a3615a of 2026-11-28, when lift-off began to end a run); not resumed, as its runs went on past lift-off, where this version's end: its 4 row(s) are kept as olderrun.csv.kept" "$TMP/err.txt"
check "and the run writes its own" cmp -s olderrun.csv whole.csv
head -n 4 older.csv >older1.csv
{ head -n 2 older.csv; tail -n 2 older.csv; } >older2.csv
{ head -n 2 whole.csv; tail -n 2 whole.csv; } >newer2.csv
sweep merge older1.csv older2.csv --out oldermerged.csv
check "an older sweep's shards still merge" cmp -s oldermerged.csv older.csv
refuses "an older shard and one of this version do not, the older named" \
  "merge: newer2.csv and older1.csv have different headers \(older1.csv was written by a plinth-sweep older than its lift_off column" \
  merge older1.csv newer2.csv --out mixed.csv
sed '3s/^0\.2,/0.25,/' whole.csv >offgrid.csv
cp offgrid.csv offgrid.orig
refuses "a row off the grid stops the run, naming it" "offgrid.csv: row '0.25' is not a point of this sweep's grid" \
  "${SMALL[@]}" --out offgrid.csv
check "and leaves the file as it was" cmp -s offgrid.csv offgrid.orig

# Interrupt: SIGINT once a row is written; the rows so far are kept; a rerun resumes.
LONG=(--scene "$ISOLATED" --record "$AT2" --param mu_s --from 0.3 --to 1.5 --steps 9
      --pga-max 4g --tol 0.02g --dt 4e-3 --jobs 1)
"$SWEEP" "${LONG[@]}" --out cut.csv >"$TMP/out.txt" 2>"$TMP/err.txt" &
pid=$!
for _ in $(seq 1 600); do
  if [[ -f cut.csv.partial ]] && (($(wc -l <cut.csv.partial) >= 3)); then break; fi
  sleep 0.05
done
kill -INT "$pid"
wait "$pid"
RC=$?
check "SIGINT ends the run with exit code 130" test "$RC" -eq 130
check "and says how many rows it kept and how to resume" \
  grep -Eq 'interrupted: [0-9]+ of 9 rows kept in cut.csv.*run the same command again to resume' "$TMP/err.txt"
kept=$(grep -c '^[01]\.' cut.csv)
check "the rows finished so far are in the file, in order" test "$kept" -ge 1 -a "$kept" -lt 9
check "the partial file is gone" test ! -e cut.csv.partial
sweep "${LONG[@]}" --out cut.csv
check "the rerun resumes from the kept rows" grep -q "$kept resumed from cut.csv" "$TMP/out.txt"
sweep "${LONG[@]}" --fresh --out uncut.csv
check "the resumed file equals an uninterrupted run byte for byte" cmp -s cut.csv uncut.csv
# A kill leaves cut.csv.partial: its rows are resumed too.
head -n 4 uncut.csv >killed.csv.partial
sweep "${LONG[@]}" --out killed.csv
check "rows of a killed run's partial file are resumed" grep -q "2 resumed from killed.csv" "$TMP/out.txt"
check "and the result is the same" cmp -s killed.csv uncut.csv

# The progress bar on a terminal (script(1) gives the program one).
if command -v script >/dev/null 2>&1; then
  script -qec "$SWEEP ${SMALL[*]} --out tty.csv --fresh" /dev/null >"$TMP/tty.txt" 2>&1
  check "a progress bar on a terminal" grep -q '4/4 rows' "$TMP/tty.txt"
fi

# The other modes, small.
sweep --scene "$ISOLATED" --record "$AT2" --param lambda --from 3 --to 4 --steps 2 \
  --param2 epsilon --from2 -0.3 --to2 0.3 --steps2 2 --event rocking --pga-max 4g --tol 0.05g \
  --dt 2e-3 --out map2.csv
check "a two-parameter map has a row per cell" test "$RC" -eq 0 -a "$(tail -n +3 map2.csv | wc -l)" -eq 4
check "its header is p1,p2,event" grep -qx 'lambda,epsilon,rocking' map2.csv
sweep --scene "$ISOLATED" --impulse-map --mu-from 0.1 --mu-to 0.6 --mu-steps 3 \
  --impulse-from 0.5 --impulse-to 2.5 --impulse-steps 3 --out imap.csv
check "an impulse map has a row per grid point" test "$RC" -eq 0 -a "$(tail -n +3 imap.csv | wc -l)" -eq 9
check "its header" grep -qx 'mu_s,impulse,simulated,predicted,c_s,c_r,c_sr,c_rs' imap.csv
sweep --scene "$ISOLATED" --impulse-curve --param T --from 1.5 --to 2.5 --steps 2 \
  --impulse-max 5 --impulse-tol 0.01 --out icurve.csv
check "an impulse curve has a row per value" test "$RC" -eq 0 -a "$(tail -n +3 icurve.csv | wc -l)" -eq 2

# The isolated and the non-isolated system side by side (--compare-ground).
# simulations N: the simulations the last run's summary reports.
simulations() { grep -o '[0-9]* simulations' "$TMP/out.txt" | cut -d' ' -f1; }
sweep "${SMALL[@]}" --jobs 2 --compare-ground --out cmp.csv
check "--compare-ground writes its map" test "$RC" -eq 0 -a -s cmp.csv
check "its settings line says compare=ground" \
  grep -q '^# plinth-sweep thresholds grid=mu_s:0.2:0.5:4 scene=.* compare=ground$' cmp.csv
check "its header adds the ground's events, suffixed _ground" grep -qx \
  'mu_s,sliding,rocking,slide_rocking,out_of_base,base_stop_hit,slide_stop_hit,fell,overturned,lift_off,sliding_ground,rocking_ground,slide_rocking_ground,overturned_ground,lift_off_ground' cmp.csv
check "the scene's own columns are those of the run without it" \
  cmp -s <(tail -n +3 cmp.csv | cut -d, -f1-10) <(tail -n +3 whole.csv)
sweep --scene "$SCENES/non-isolated.toml" --record "$AT2" --param mu_s --from 0.2 --to 0.5 \
  --steps 4 --pga-max 4g --tol 0.05g --dt 4e-3 --out ground.csv
check "the ground columns are those of a run of non-isolated.toml" \
  cmp -s <(tail -n +3 cmp.csv | cut -d, -f11-15) <(tail -n +3 ground.csv | cut -d, -f2-4,9,10)
check "and the block on the ground rocks there" test -n "$(tail -n +3 ground.csv | cut -d, -f3 | tr -d '\n')"
PERIOD=(--scene "$ISOLATED" --record "$AT2" --param T --from 1 --to 3 --steps 3 --pga-max 4g
        --tol 0.05g --dt 4e-3 --jobs 2)
sweep "${PERIOD[@]}" --compare-ground --out cmpT.csv
compared=$(simulations)
sweep "${PERIOD[@]}" --out plainT.csv
plain=$(simulations)
sweep --scene "$SCENES/non-isolated.toml" --record "$AT2" --param epsilon --from 0 --to 0 \
  --steps 1 --pga-max 4g --tol 0.05g --dt 4e-3 --out ground1.csv
alone=$(simulations)
check "against T (the ground has none) every row holds the one ground row" test \
  "$(tail -n +3 cmpT.csv | cut -d, -f11-13 | sort -u)" = "$(tail -n +3 ground1.csv | cut -d, -f3,9,10)"
check "its header has only rocking, overturned and lift_off (no friction)" grep -q ',lift_off,rocking_ground,overturned_ground,lift_off_ground$' cmpT.csv
check "and the ground was searched once" test "$compared" -eq $((plain + alone))
# Shards, merge and resume with the ground's columns (on the T sweep: cheap).
sweep "${PERIOD[@]}" --compare-ground --shard 2/2 --out cmpT2.csv
sweep "${PERIOD[@]}" --compare-ground --shard 1/2 --out cmpT1.csv
sweep merge --out cmpTmerged.csv cmpT2.csv cmpT1.csv
check "compared shards merged equal the whole run byte for byte" cmp -s cmpTmerged.csv cmpT.csv
refuses "merge refuses shards with and without --compare-ground" \
  "different sweeps .*compare: none in plainT.csv, ground in cmpT1.csv" merge --out m.csv cmpT1.csv plainT.csv
cp cmpT.csv cmpTagain.csv
sweep "${PERIOD[@]}" --compare-ground --out cmpTagain.csv
check "a compared sweep is resumed" grep -q '3 resumed from cmpTagain.csv), 0 simulations' "$TMP/out.txt"
check "and its file is unchanged" cmp -s cmpTagain.csv cmpT.csv
head -n 3 cmpT.csv >cmpTkilled.csv.partial
sweep "${PERIOD[@]}" --compare-ground --out cmpTkilled.csv
check "rows of a killed compared run are resumed" grep -q "1 resumed from cmpTkilled.csv" "$TMP/out.txt"
check "and the result is the same" cmp -s cmpTkilled.csv cmpT.csv
cp plainT.csv plainfirst.csv
sweep "${PERIOD[@]}" --compare-ground --out plainfirst.csv
check "a map made without --compare-ground is replaced, saying why" \
  grep -q "another sweep (compare: none in the file, ground in this run)" "$TMP/err.txt"
check "and keeping its rows beside" cmp -s plainfirst.csv.kept plainT.csv
check "by the compared map" cmp -s plainfirst.csv cmpT.csv
sweep --scene "$ISOLATED" --record "$AT2" --param lambda --from 3 --to 4 --steps 2 \
  --param2 epsilon --from2 -0.3 --to2 0.3 --steps2 2 --event rocking --pga-max 4g --tol 0.05g \
  --dt 2e-3 --compare-ground --out cmpmap2.csv
check "a compared two-parameter map adds <event>_ground" grep -qx 'lambda,epsilon,rocking,rocking_ground' cmpmap2.csv
check "and keeps the map's own column" cmp -s <(tail -n +3 cmpmap2.csv | cut -d, -f1-3) <(tail -n +3 map2.csv)
sweep --scene "$ISOLATED" --impulse-curve --param T --from 1.5 --to 2.5 --steps 2 \
  --impulse-max 5 --impulse-tol 0.01 --compare-ground --out cmpicurve.csv
check "a compared impulse curve adds the ground's overturning" grep -qx \
  'T,rocking,overturned,rocking_closed_form,overturned_closed_form,lift_off,overturned_ground,overturned_closed_form_ground,lift_off_ground' cmpicurve.csv
check "and keeps the curve's own columns" cmp -s <(tail -n +3 cmpicurve.csv | cut -d, -f1-6) <(tail -n +3 icurve.csv)
refuses "--compare-ground on a scene without a base" "--compare-ground: the scene has no \[base\]" \
  --scene "$SCENES/non-isolated.toml" --record "$AT2" --param mu_s --from 0.2 --to 0.5 --steps 2 \
  --compare-ground --out x.csv
refuses "--compare-ground with an event the ground cannot have" \
  "--compare-ground: the block on the ground cannot have base_stop_hit \(it has no base stops\)" \
  --scene "$SCENES/paper-isolated-stops.toml" --record "$AT2" --param lambda --from 3 --to 4 \
  --steps 2 --param2 epsilon --from2 0 --to2 0.2 --steps2 2 --event base_stop_hit --compare-ground --out x.csv
refuses "--compare-ground with --impulse-map" "--compare-ground: not with --impulse-map" \
  --scene "$ISOLATED" --impulse-map --mu-from 0.1 --mu-to 1 --mu-steps 2 --impulse-from 0.1 \
  --impulse-to 1 --impulse-steps 2 --compare-ground --out x.csv

# Plots: PNG and SVG of the same stem, or a clear error naming the package.
if command -v gnuplot >/dev/null 2>&1; then
  for csv in whole map2 imap icurve cmp cmpT cmpmap2 cmpicurve; do
    sweep plot "$csv.csv" --out "plot-$csv.png"
    check "$csv: plot writes a PNG" test "$RC" -eq 0 -a "$(head -c 4 "plot-$csv.png" | tail -c 3)" = PNG
    check "$csv: and an SVG" grep -q '<svg' "plot-$csv.svg"
  done
  check "cmp: the ground's curves are drawn thin" grep -q "rocking_ground using 1:2 with linespoints .* lw 1 .*on the ground'" plot-cmp.gp
  check "cmpT: against T, on the axis" grep -q "rocking_ground using 1:2 with points .*no base: on the axis" plot-cmpT.gp
  check "cmpmap2: the ground's map beside the scene's" grep -q "set multiplot layout 1,2" plot-cmpmap2.gp
  check "cmpmap2: its SVG has both panels" grep -q "on the ground" plot-cmpmap2.svg
  check "cmpicurve: the ground's overturning on the axis" grep -q "overturned_ground using 1:2 with points" plot-cmpicurve.gp
  sweep plot older.csv --out plot-older.png
  check "an older plinth-sweep's file plots" test "$RC" -eq 0 -a -s plot-older.png -a -s plot-older.svg
  check "without the lift_off curve, saying why" \
    grep -q "the CSV was written by a plinth-sweep older than its lift_off column .*; plotted without it: its runs went on past lift-off" "$TMP/err.txt"
  bash "$SRC/tools/plot-sweep.sh" whole.csv wrapped.png >"$TMP/out.txt" 2>"$TMP/err.txt"
  RC=$?
  check "tools/plot-sweep.sh plots a CSV" test "$RC" -eq 0 -a -s wrapped.png -a -s wrapped.svg
else
  echo "# gnuplot not installed: plot checks skipped (apt-get install gnuplot-nox)"
fi
mkdir -p nogp
PATH=$TMP/nogp "$SWEEP" "${SMALL[@]}" --out nogp.csv --plot nogp.png >"$TMP/out.txt" 2>"$TMP/err.txt"
RC=$?
check "a missing gnuplot is named, with its package" \
  test "$RC" -eq 1 -a -n "$(grep 'gnuplot-nox' "$TMP/err.txt")"
check "and the sweep did not run first" test ! -e nogp.csv

# Bad inputs.
refuses "unknown parameter" "--param: unknown parameter 'mu' \(one of mu_s" \
  --scene "$ISOLATED" --record "$AT2" --param mu --from 0.1 --to 1 --steps 3 --out x.csv
refuses "--from above --to" "--from 1 is greater than --to 0.1" \
  --scene "$ISOLATED" --record "$AT2" --param mu_s --from 1 --to 0.1 --steps 3 --out x.csv
refuses "no steps" "--steps: must be at least 1" \
  --scene "$ISOLATED" --record "$AT2" --param mu_s --from 0.1 --to 1 --steps 0 --out x.csv
refuses "a missing --param" "--param is required" \
  --scene "$ISOLATED" --record "$AT2" --from 0.1 --to 1 --steps 3 --out x.csv
refuses "an unreadable record" "nothere.AT2" \
  --scene "$ISOLATED" --record nothere.AT2 --param mu_s --from 0.1 --to 1 --steps 3 --out x.csv
refuses "a parameter the scene lacks" "--param u_max = 0.1: the scene has no \[base_stops\]" \
  --scene "$ISOLATED" --record "$AT2" --param u_max --from 0.1 --to 0.2 --steps 2 --out x.csv
refuses "a bad shard" "--shard: expected i/N" "${SMALL[@]}" --shard 3/2 --out x.csv
refuses "no jobs" "--jobs: must be at least 1" "${SMALL[@]}" --jobs 0 --out x.csv
refuses "an unknown event" "--event: unknown event 'toppled'" "${SMALL[@]}" --param2 epsilon \
  --from2 0 --to2 0.2 --steps2 2 --event toppled --out x.csv
refuses "a second parameter without its range" "--from2 is required" "${SMALL[@]}" \
  --param2 epsilon --out x.csv
refuses "a plot name without .png or .svg" "--plot: expected a file name ending in .png or .svg" \
  "${SMALL[@]}" --out x.csv --plot map.jpg
refuses "an impulse map on the ground" "needs a scene with a \[base\]" \
  --scene "$SCENES/non-isolated.toml" --impulse-map --mu-from 0.1 --mu-to 1 --mu-steps 2 \
  --impulse-from 0.1 --impulse-to 1 --impulse-steps 2 --out x.csv
refuses "an impulse map with a record" "excludes" --scene "$ISOLATED" --record "$AT2" \
  --impulse-map --mu-from 0.1 --mu-to 1 --mu-steps 2 --impulse-from 0.1 --impulse-to 1 \
  --impulse-steps 2 --out x.csv
refuses "impulse steps from above to" "--mu-from 1 is greater than --mu-to 0.1" \
  --scene "$ISOLATED" --impulse-map --mu-from 1 --mu-to 0.1 --mu-steps 2 --impulse-from 0.1 \
  --impulse-to 1 --impulse-steps 2 --out x.csv
refuses "an output that cannot be written" "cannot open for writing|folder .* does not exist" "${SMALL[@]}" \
  --out /nonexistent/dir/x.csv

echo "$PASSED passed, $FAILED failed"
((FAILED == 0))
