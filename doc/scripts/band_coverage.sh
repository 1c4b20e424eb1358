#!/bin/sh
# Coverage of the forecast's 10-90 % bands against `pvtwin sim` (not in CI).
# For each (start date, seed): 28 days of the demo plant (heat-pump
# operation), the daily forecast with fixed parameters (--params) and
# persisted weather, a 7- and a 14-day window, 14 test days; prints the
# "all N days" line of `pvtwin backtest --forecast` (coverage P_el, Q_u).
#
#   doc/scripts/band_coverage.sh PVTWIN SIM_TOML PARAMS_JSON OUTDIR dev|final
#
# dev: the dates and seeds the band rule was developed on; final: those it
# was checked on once per design.
set -eu
pvtwin=$1 sim=$2 params=$3 out=$4 set=$5
case $set in
  dev) runs="2026-11-01:1 2025-06-01:2" ;;
  final) runs="2025-03-01:5 2025-09-01:6" ;;
  *) echo "dev or final" >&2; exit 2 ;;
esac
mkdir -p "$out"
for run in $runs; do
  start=${run%%:*} seed=${run##*:}
  csv=$out/sim-$start-$seed.csv
  [ -f "$csv" ] || "$pvtwin" sim --config "$sim" --export "$csv" --days 28 --step 60 \
    --start "$start" --seed "$seed" >/dev/null 2>&1
  for window in 7 14; do
    printf '%s seed %s window %2s: ' "$start" "$seed" "$window"
    "$pvtwin" backtest --forecast --config "$sim" --csv "$csv" --params "$params" \
      --train-days "$window" --first-test-day "$(date -u -d "$start + 14 days" +%F)" \
      --test-days 14 2>/dev/null | grep '^all [0-9]* days  ' | sed 's/  */ /g'
  done
done
