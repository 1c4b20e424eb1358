#!/bin/sh
# MAE, skill and band coverage of the daily forecast with persisted weather
# against `pvtwin sim` (not in CI: about 2 min per seed on two cores).
#
#   doc/scripts/persistence_skill.sh PVTWIN OUTDIR dev|final|weeks [SIGMA]
#
# The example plant (config/examples/sim-plant.toml, truth
# 2N2CrI+wind+transport_delay); parameters of 2N1Ccolwr identified once on
# the first 14 days of seed 1 from 2025-04-01 and kept fixed (--params), so
# that only the forecast's inputs and bands differ between two builds.
#   dev, final  110 days from 2025-04-01 (seeds 1-3; 4-6), 76 test days
#               from 2025-04-30 (a 14-day window before each);
#   weeks       the week of doc/scripts/week_against_sim.sh offline: 28 days
#               of history from 2025-05-12, then the week 2025-06-09 to -15
#               (seeds 1-10).
# With SIGMA the forecast has a weather forecast instead of persisted
# weather: each seed's hourly weather with an AR(1) error of that size
# (doc/scripts/weather_forecast_with_error.py, its seed the plant's), as
# `week_against_sim.sh` with FORECAST_SIGMA.
# Prints the "all N days" line of `pvtwin backtest --forecast` per seed:
# MAE P_el, skill, coverage, MAE Q_u, skill, coverage.
set -eu
pvtwin=$1 out=$2 set=$3 sigma=${4:-}
here=$(cd "$(dirname "$0")/../.." && pwd)
config=$here/config/examples/sim-plant.toml
mkdir -p "$out"
params=$out/params.json
if [ ! -f "$params" ]; then
  "$pvtwin" sim --config "$config" --export "$out/long-1.csv" --days 110 --step 60 \
    --start 2025-04-01 --seed 1 >/dev/null 2>&1
  "$pvtwin" calibrate --config "$config" --csv "$out/long-1.csv" --variant 2N1Ccolwr \
    --train-end 2025-04-15 --out "$params" >/dev/null 2>&1
fi
case $set in
  dev) seeds="1 2 3" ;;
  final) seeds="4 5 6" ;;
  weeks) seeds="1 2 3 4 5 6 7 8 9 10" ;;
  *) echo "dev, final or weeks" >&2; exit 2 ;;
esac
for seed in $seeds; do
  if [ "$set" = weeks ]; then
    csv=$out/week-$seed.csv start=2025-05-12 days=35 first=2025-06-09 tests=7
  else
    csv=$out/long-$seed.csv start=2025-04-01 days=110 first=2025-04-30 tests=76
  fi
  [ -f "$csv" ] || "$pvtwin" sim --config "$config" --export "$csv" --days "$days" --step 60 \
    --start "$start" --seed "$seed" >/dev/null 2>&1
  set --
  if [ -n "$sigma" ]; then
    python3 "$here/doc/scripts/weather_forecast_with_error.py" "$csv" "$out/wf-$seed.csv" \
      "$sigma" "$seed"
    set -- --weather "$out/wf-$seed.csv"
  fi
  printf 'seed %2s: ' "$seed"
  "$pvtwin" backtest --forecast --config "$config" --csv "$csv" --params "$params" \
    --train-days 14 --first-test-day "$first" --test-days "$tests" "$@" 2>/dev/null |
    grep '^all [0-9]* days  ' | sed 's/  */ /g'
done
