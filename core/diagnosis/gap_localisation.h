// "Where" of the gap diagnosis: in which regimes of the plant the model's
// held-out error concentrates, beyond what the regime's share of the data
// explains, and how unusual that concentration is.
//
// For one output (P_el or Q_u) with residuals r_i = predicted − measured over
// the objective rows, and a regime driver x (hour of day, AOI, irradiance, …)
// cut into bins, each bin B gets
//   share_of_rows      = n_B / n
//   share_of_abs_error = Σ_{i∈B} |r_i| / Σ_i |r_i|
//   bias_w             = mean_{i∈B} r_i,   mae_w = mean_{i∈B} |r_i|
//   z                  = (share_of_abs_error − share_of_rows) / sd*
// where sd* is the standard deviation of that excess over bootstrap
// resamples of whole time blocks (LocaliseOptions::block_s, default one
// hour): residuals are autocorrelated, so rows are not independent, but
// blocks that long nearly are. A bin is a region of concentrated error if
// z ≥ min_z, share_of_abs_error / share_of_rows ≥ min_ratio and it holds at
// least min_rows rows; adjacent flagged bins of a 1-D driver are merged into
// one range (and re-tested). Two-dimensional cells (sun azimuth × elevation)
// work the same with a second driver. The driver named "day" is the
// exception: days are the blocks themselves, so a day's z is the robust
// z-score of its MAE among the days, (MAE_d − median)/(1.4826·MAD), and days
// are not merged.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/common/plant.h"
#include "core/common/series.h"
#include "core/model/thermal_model.h"

namespace pvtwin {

// A driver that bins rows. values[i] is row i's value (NaN: the row has no
// value and is in no bin); bin k is [edges[k], edges[k+1]). With name2 set,
// bins are cells of the product with the second driver.
struct RegimeDriver {
  std::string name;  // e.g. "aoi_deg", "hour_of_day", "day"
  std::vector<double> values;
  std::vector<double> edges;
  std::vector<std::string> labels;  // optional text per bin of the first driver (e.g. dates)
  std::string name2;                // second dimension, empty for 1-D
  std::vector<double> values2;
  std::vector<double> edges2;
};

struct GapRegion {
  std::string driver;
  double lower = 0.0, upper = 0.0;  // range [lower, upper) of the driver
  std::string driver2;              // second driver of a 2-D cell, else empty
  double lower2 = 0.0, upper2 = 0.0;
  std::string label;   // e.g. the date of a day
  std::string output;  // "p_el" or "q_th"
  std::size_t rows = 0;
  double share_of_rows = 0.0;
  double share_of_abs_error = 0.0;
  double bias_w = 0.0;  // mean residual (predicted − measured)
  double mae_w = 0.0;   // mean absolute residual in the region
  double z = 0.0;       // block-bootstrap z of the excess share
  bool flagged = false;
};

struct LocaliseOptions {
  double block_s = 3600.0;       // bootstrap block length, > 0
  int bootstrap_samples = 300;   // ≥ 20
  double min_z = 3.0;            // flag threshold on z, > 0
  double min_ratio = 1.3;        // flag threshold on share_of_abs_error / share_of_rows, ≥ 1
  std::size_t min_rows = 10;     // fewer rows: never flagged
  std::size_t max_regions = 12;  // regions kept per output: most excess first, ≤ 2 per driver
  std::uint64_t seed = 1;        // of the bootstrap draws
  bool IsValid(std::string* why) const;
};

struct Localisation {
  std::vector<GapRegion> bins;     // every non-empty bin of every driver
  std::vector<GapRegion> regions;  // flagged regions, merged, most excess share first
  double total_abs_error_w = 0.0;  // Σ|r| / n (the output's MAE)
};

// Localises the error of one output. residual[i] NaN: row i is not counted.
Localisation LocaliseGap(std::span<const std::int64_t> time_s, std::span<const double> residual,
                         const std::string& output, const std::vector<RegimeDriver>& drivers,
                         const LocaliseOptions& options);

// The standard regime drivers of a data set (rows of `series`, the drivers
// built from it): hour_of_day (local mean solar time, 2 h bins), day (local
// solar days, labelled with their dates), aoi_deg, g_poa_w_m2,
// g_poa_rate_w_m2_min (|ΔG|/Δt to the previous row), beam_fraction (from
// g_poa_diffuse_w_m2 or ghi/dhi), wind_m_s, sky_deficit_k (T_amb − T_sky),
// t_in_minus_t_amb_k, flow_on (0/1), flow_kg_s (quintiles of running flow),
// min_since_pump_switch, and the cells sun_azimuth_deg × sun_elevation_deg.
// Drivers whose channels are missing are left out.
std::vector<RegimeDriver> StandardRegimeDrivers(const Series& series, const Drivers& drivers,
                                                const Plant& plant);

}  // namespace pvtwin
