#!/usr/bin/env python3
"""A weather-forecast file for `pvtwin backtest --forecast` from a plant CSV.

The hourly means of the exported plant's weather (g_poa_w_m2, ghi_w_m2,
dhi_w_m2, t_amb_c, wind_m_s) as a canonical weather CSV, with a day-ahead
forecast's error: the irradiance times exp(e), e an hourly AR(1) with
rho = 0.7 and standard deviation sigma; the air temperature plus an AR(1)
of 4 * sigma K. The same law as tests/unit/test_forecast_backtest_cli.cc
(which draws its own numbers).

usage: weather_forecast_with_error.py PLANT_CSV OUT_CSV SIGMA SEED
"""
import csv
import math
import random
import sys

NAMES = ["g_poa_w_m2", "ghi_w_m2", "dhi_w_m2", "t_amb_c", "wind_m_s"]


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    src, out, sigma, seed = sys.argv[1], sys.argv[2], float(sys.argv[3]), int(sys.argv[4])
    random.seed(seed)
    hours = {}
    with open(src, newline="") as f:
        for row in csv.DictReader(f):
            hours.setdefault(row["time"][:13], []).append(row)
    e_g = e_t = 0.0
    innovation = math.sqrt(1 - 0.7 ** 2)
    with open(out, "w") as f:
        f.write("time," + ",".join(NAMES) + "\n")
        for hour in sorted(hours):
            e_g = 0.7 * e_g + innovation * sigma * random.gauss(0, 1)
            e_t = 0.7 * e_t + innovation * 4 * sigma * random.gauss(0, 1)
            rows = hours[hour]
            mean = [sum(float(r[n]) for r in rows) / len(rows) for n in NAMES]
            values = [mean[0] * math.exp(e_g), mean[1] * math.exp(e_g), mean[2] * math.exp(e_g),
                      mean[3] + e_t, mean[4]]
            f.write(hour + ":00:00Z," + ",".join("%.3f" % v for v in values) + "\n")


if __name__ == "__main__":
    main()
