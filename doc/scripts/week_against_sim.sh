#!/bin/sh
# A week of operation against `pvtwin sim` (not in CI: about 35 min of wall time).
#
#   doc/scripts/week_against_sim.sh PVTWIN OUTDIR healthy|clipping|shading [SEED] [START]
#
# 28 days of history of the example plant (config/examples/sim-plant.toml,
# truth 2N2CrI+wind+transport_delay, seed SEED) are exported and imported, so
# that the daemon starts as a plant in its second month. Then `pvtwin sim`
# serves the same plant over Modbus TCP on loopback and `pvtwin run` (model
# 2N1Ccolwr, nightly calibration over 14 days at 02:00 Europe/Vienna, hourly
# forecasts, daily checks, weekly diagnosis) polls it for seven simulated days
# from START 00:00 UTC at 300 simulated seconds per wall second. With
# `clipping` the served plant has an inverter that clips P_el (+pv_clipping)
# from START on: the history is healthy, the week is not; with `shading` an
# obstacle (+shading, a box in the west-south-west) stands from START on.
#
# It prints what an operator would check after the week: nightly fits taken,
# the forecast band's coverage per output and day, the performance index band
# holding 1, the performance alarms and the diagnoses. The store, both logs
# and the configs stay in OUTDIR. Defaults: SEED 1, START 2025-06-09 (a
# Monday).
#
# With FORECAST_SIGMA set (e.g. FORECAST_SIGMA=0.15) the daemon also has a
# weather forecast, as a plant with `[forecast] weather_url` has: the hourly
# means of the plant's own weather over the history and the week with an
# hourly AR(1) error of that size (doc/scripts/weather_forecast_with_error.py,
# its seed the plant's), imported into weather_forecast before the daemon
# starts. Without it the daemon persists the weather, as a plant without one.
set -eu
pvtwin=$1 out=$2 scenario=$3 seed=${4:-1} start=${5:-2025-06-09}
sigma=${FORECAST_SIGMA:-}
case $scenario in
  healthy) truth="2N2CrI+wind+transport_delay" ;;
  clipping) truth="2N2CrI+wind+transport_delay+pv_clipping" ;;
  shading) truth="2N2CrI+wind+transport_delay+shading" ;;
  *) echo "scenario: healthy, clipping or shading" >&2; exit 2 ;;
esac
here=$(cd "$(dirname "$0")/../.." && pwd)
speed=300
days=${DAYS:-7}   # DAYS=1 for a short try
t0=$(date -u -d "$start" +%s)
mkdir -p "$out"
cd "$out"
rm -f pvtwin.db pvtwin.db-wal pvtwin.db-shm daemon.log sim.log

# Ports of the two devices, apart for each scenario so that two weeks can run at once
# (PORT_OFFSET for two weeks of the same scenario).
case $scenario in healthy) offset=100 ;; clipping) offset=200 ;; shading) offset=300 ;; esac
offset=${PORT_OFFSET:-$offset}
sed -e "s/^port = 5020/port = $((5020 + offset))/" -e "s/^port = 5021/port = $((5021 + offset))/" \
  "$here/config/examples/sim-plant.toml" > sim.toml
cat sim.toml - > pvtwin.toml <<EOF

[storage]
path = "$out/pvtwin.db"

[calibration]
variant = "2N1Ccolwr"
window_days = 14
at = "02:00"
timezone = "Europe/Vienna"

[forecast]
horizon_h = 24
refresh_min = 60

[diagnosis]
enabled = true
every_days = 7

[log]
status_min = 360
EOF

echo "history: 28 days before $start (seed $seed, healthy)"
"$pvtwin" sim --config sim.toml --export history.csv --days 28 --step 60 \
  --start $((t0 - 28 * 86400)) --seed "$seed" > export.log 2>&1
"$pvtwin" import --config pvtwin.toml --csv history.csv --db pvtwin.db > import.log 2>&1
if [ -n "$sigma" ]; then
  echo "weather forecast: the plant's hourly weather with an AR(1) error of sigma $sigma"
  "$pvtwin" sim --config sim.toml --export weather-truth.csv --days $((28 + days)) --step 60 \
    --start $((t0 - 28 * 86400)) --seed "$seed" >> export.log 2>&1
  python3 "$here/doc/scripts/weather_forecast_with_error.py" weather-truth.csv \
    weather-forecast.csv "$sigma" "$seed"
  "$pvtwin" import-weather --config pvtwin.toml --db pvtwin.db weather-forecast.csv \
    > import-weather.log 2>&1
  rm -f weather-truth.csv
fi

anchor=$(date +%s)
"$pvtwin" sim --config sim.toml --speed $speed --start "$t0" \
  --wall-anchor "$anchor" --seed "$seed" --truth-variant "$truth" < /dev/null > sim.log 2>&1 &
sim_pid=$!
i=0
until grep -q '^ready' sim.log; do
  i=$((i + 1)); [ $i -lt 100 ] || { echo "pvtwin sim did not start: see $out/sim.log" >&2; exit 1; }
  sleep 0.2
done
"$pvtwin" run --config pvtwin.toml --speed $speed --sim-start "$t0" \
  --wall-anchor "$anchor" > daemon.log 2>&1 &
run_pid=$!
trap 'kill $run_pid $sim_pid 2>/dev/null || true' EXIT INT TERM

# Five simulated hours past the week, so that its last nightly fit and checks run.
wall=$(((days * 86400 + 5 * 3600) / speed))
echo "live: $days days from $start ($scenario) at ${speed}x, about $((wall / 60)) min"
elapsed=0
while [ $elapsed -lt $wall ]; do
  sleep 60
  elapsed=$(( $(date +%s) - anchor ))
  kill -0 $run_pid 2>/dev/null || { echo "the daemon stopped: see $out/daemon.log" >&2; exit 1; }
  printf '  %3d%%  simulated %s\n' $((100 * elapsed / wall)) \
    "$(date -u -d @$((t0 + elapsed * speed)) '+%F %H:%M')"
done
kill -TERM $run_pid
wait $run_pid || true
kill -TERM $sim_pid 2>/dev/null || true
trap - EXIT INT TERM

end=$((t0 + days * 86400))
sqlite3 -header -column pvtwin.db <<EOF
.print
.print == Nightly fits of the week (the first night's to the one after the last day)
SELECT status, count(*) AS fits FROM calibration
 WHERE run_at > $t0 + 3600 AND run_at < $end + 5 * 3600 GROUP BY status;
.print
.print == Forecast band (10-90 %) coverage per day, day-ahead issue
SELECT date(day, 'unixepoch') AS day, minutes, round(coverage_p_el, 2) AS cov_p_el, round(coverage_q_th, 2) AS cov_q_th,
       round(skill_p_el, 3) AS skill_p_el, round(skill_q_th, 3) AS skill_q_th
  FROM forecast_skill WHERE day >= $t0 AND day < $end ORDER BY day;
SELECT 'week' AS day, sum(minutes) AS minutes,
       round(sum(coverage_p_el * minutes) / sum(minutes), 3) AS cov_p_el,
       round(sum(coverage_q_th * minutes) / sum(minutes), 3) AS cov_q_th
  FROM forecast_skill WHERE day >= $t0 AND day < $end;
.print
.print == Points outside their own band (forecast rows of the week)
SELECT count(*) AS rows,
       sum(p_el_w < p_el_w_p10 - 1e-9 OR p_el_w > p_el_w_p90 + 1e-9) AS p_el_outside,
       sum(q_th_w < q_th_w_p10 - 1e-9 OR q_th_w > q_th_w_p90 + 1e-9) AS q_th_outside
  FROM forecast WHERE issued_at >= $t0 AND issued_at < $end;
.print
.print == Performance index and its band
SELECT date(day, 'unixepoch') AS day, round(pi_el, 3) AS pi_el, round(pi_el_low, 3) AS el_low, round(pi_el_high, 3) AS el_high,
       round(pi_th, 3) AS pi_th, round(pi_th_low, 3) AS th_low, round(pi_th_high, 3) AS th_high
  FROM performance_daily WHERE day >= $t0 AND day < $end ORDER BY day;
SELECT sum(pi_el_low <= 1 AND 1 <= pi_el_high) || ' of ' || count(pi_el_low) AS el_band_holds_1,
       sum(pi_th_low <= 1 AND 1 <= pi_th_high) || ' of ' || count(pi_th_low) AS th_band_holds_1
  FROM performance_daily WHERE day >= $t0 AND day < $end;
.print
.print == Performance alarms of the week
SELECT datetime(ts, 'unixepoch') AS at, kind, message FROM monitor_event
 WHERE kind LIKE 'performance_%' AND ts >= $t0 ORDER BY ts;
.print
.print == Diagnoses (the first on the history; after an alarm on the days since the change;
.print    the first and last solar day judged)
SELECT datetime(run_at, 'unixepoch') AS at, date(window_start + 43200, 'unixepoch') AS from_day,
       date(window_end - 43200, 'unixepoch') AS to_day, verdict, low_confidence
  FROM diagnosis ORDER BY run_at;
EOF
