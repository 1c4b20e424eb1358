#include "core/diagnosis/gap_localisation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <sstream>

#include "core/common/calendar.h"
#include "core/common/units.h"
#include "core/model/irradiance_drivers.h"
#include "core/physics/sky_radiation.h"
#include "core/physics/solar_position.h"

namespace pvtwin {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
const double kNaN = std::nan("");

// Bin of v in edges (k with edges[k] ≤ v < edges[k+1]), or -1.
int BinOf(double v, const std::vector<double>& edges) {
  if (!std::isfinite(v) && !std::isinf(v)) return -1;
  if (edges.size() < 2 || v < edges.front() || v >= edges.back()) return -1;
  const auto it = std::upper_bound(edges.begin(), edges.end(), v);
  return static_cast<int>(it - edges.begin()) - 1;
}

// Per-block sums of one region: |r| and row counts, dense over blocks.
struct BlockSums {
  std::vector<double> abs_error;
  std::vector<double> rows;
  std::vector<double> residual;  // Σ r (for the bias)
};

// The bootstrap: draws[s][b] = how often block b is in resample s.
struct Bootstrap {
  std::vector<std::vector<int>> draws;
  BlockSums total;
};

GapRegion Evaluate(const BlockSums& region, const Bootstrap& boot, const LocaliseOptions& opt) {
  GapRegion g;
  double e = 0.0, n = 0.0, r = 0.0, te = 0.0, tn = 0.0;
  for (std::size_t b = 0; b < region.rows.size(); ++b) {
    e += region.abs_error[b];
    n += region.rows[b];
    r += region.residual[b];
    te += boot.total.abs_error[b];
    tn += boot.total.rows[b];
  }
  g.rows = static_cast<std::size_t>(n);
  if (n <= 0.0 || tn <= 0.0) return g;
  g.share_of_rows = n / tn;
  g.share_of_abs_error = te > 0.0 ? e / te : 0.0;
  g.bias_w = r / n;
  g.mae_w = e / n;
  const double excess = g.share_of_abs_error - g.share_of_rows;
  double sum = 0.0, sum2 = 0.0;
  int count = 0;
  for (const std::vector<int>& draw : boot.draws) {
    double se = 0.0, sn = 0.0, ste = 0.0, stn = 0.0;
    for (std::size_t b = 0; b < draw.size(); ++b) {
      if (draw[b] == 0) continue;
      const double c = draw[b];
      se += c * region.abs_error[b];
      sn += c * region.rows[b];
      ste += c * boot.total.abs_error[b];
      stn += c * boot.total.rows[b];
    }
    if (ste <= 0.0 || stn <= 0.0) continue;
    const double x = se / ste - sn / stn;
    sum += x;
    sum2 += x * x;
    ++count;
  }
  double sd = 0.0;
  if (count > 1) {
    const double mean = sum / count;
    sd = std::sqrt(std::max(0.0, (sum2 - count * mean * mean) / (count - 1)));
  }
  g.z = sd > 0.0 ? excess / sd : (excess > 0.0 ? kInf : 0.0);
  g.flagged = g.z >= opt.min_z && g.share_of_rows > 0.0 &&
              g.share_of_abs_error / g.share_of_rows >= opt.min_ratio && g.rows >= opt.min_rows;
  return g;
}

void Add(BlockSums* to, const BlockSums& from) {
  for (std::size_t b = 0; b < to->rows.size(); ++b) {
    to->abs_error[b] += from.abs_error[b];
    to->rows[b] += from.rows[b];
    to->residual[b] += from.residual[b];
  }
}

}  // namespace

bool LocaliseOptions::IsValid(std::string* why) const {
  std::ostringstream out;
  if (!(block_s > 0.0)) out << "block_s = " << block_s << ": must be > 0; ";
  if (bootstrap_samples < 20)
    out << "bootstrap_samples = " << bootstrap_samples << ": must be ≥ 20; ";
  if (!(min_z > 0.0)) out << "min_z = " << min_z << ": must be > 0; ";
  if (!(min_ratio >= 1.0)) out << "min_ratio = " << min_ratio << ": must be ≥ 1; ";
  const std::string text = out.str();
  if (why != nullptr) *why = text.empty() ? "" : text.substr(0, text.size() - 2);
  return text.empty();
}

namespace {

// Blocks of block_s from the first counted row: the block of each row (−1
// for rows without a residual), *blocks their number.
std::vector<int> AssignBlocks(std::span<const std::int64_t> time_s,
                              std::span<const double> residual, std::size_t n, double block_s,
                              int* blocks) {
  std::vector<int> block(n, -1);
  std::int64_t first = 0;
  bool have_first = false;
  std::map<std::int64_t, int> index;
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(residual[i])) continue;
    if (!have_first) {
      first = time_s[i];
      have_first = true;
    }
    const auto key =
        static_cast<std::int64_t>(std::floor(static_cast<double>(time_s[i] - first) / block_s));
    auto [it, inserted] = index.emplace(key, *blocks);
    if (inserted) ++*blocks;
    block[i] = it->second;
  }
  return block;
}

// Names the region: bins k1_lo … k1_hi of the driver (and bin k2 of its
// second dimension).
void Describe(const RegimeDriver& d, const std::string& output, std::size_t k1_lo,
              std::size_t k1_hi, std::size_t k2, GapRegion* g) {
  g->driver = d.name;
  g->output = output;
  g->lower = d.edges[k1_lo];
  g->upper = d.edges[k1_hi + 1];
  if (k1_lo == k1_hi && k1_lo < d.labels.size()) g->label = d.labels[k1_lo];
  if (k1_lo != k1_hi && k1_hi < d.labels.size()) {
    g->label = d.labels[k1_lo] + " … " + d.labels[k1_hi];
  }
  if (!d.name2.empty()) {
    g->driver2 = d.name2;
    g->lower2 = d.edges2[k2];
    g->upper2 = d.edges2[k2 + 1];
  }
}

void JudgeDays(const LocaliseOptions& options, std::vector<GapRegion>* evaluated,
               std::vector<GapRegion>* candidates, std::vector<GapRegion>* bins) {
  // Days are the blocks themselves: a day's excess is judged against the
  // other days, by the robust z of its MAE (median, 1.4826·MAD).
  std::vector<double> maes;
  for (const GapRegion& g : *evaluated) {
    if (g.rows > 0) maes.push_back(g.mae_w);
  }
  if (maes.size() >= 3) {
    std::vector<double> sorted = maes;
    std::sort(sorted.begin(), sorted.end());
    const double median = sorted[sorted.size() / 2];
    for (double& v : sorted) v = std::fabs(v - median);
    std::sort(sorted.begin(), sorted.end());
    const double mad = 1.4826 * sorted[sorted.size() / 2];
    for (GapRegion& g : *evaluated) {
      if (g.rows == 0) continue;
      const double excess = g.mae_w - median;
      g.z = mad > 0.0 ? excess / mad : (excess > 0.0 ? kInf : 0.0);
      g.flagged = g.z >= options.min_z && g.share_of_rows > 0.0 &&
                  g.share_of_abs_error / g.share_of_rows >= options.min_ratio &&
                  g.rows >= options.min_rows;
      if (g.flagged) candidates->push_back(g);
    }
    for (GapRegion& b : *bins) {
      for (const GapRegion& g : *evaluated) {
        if (b.driver == g.driver && b.lower == g.lower && b.output == g.output) b = g;
      }
    }
  }
}

// Merges runs of adjacent flagged bins of a one-dimensional driver into one
// region when the run as a whole is flagged; else keeps the bins.
void MergeFlaggedRuns(const RegimeDriver& d, const std::string& output,
                      const std::vector<BlockSums>& sums, const std::vector<GapRegion>& evaluated,
                      const Bootstrap& boot, const LocaliseOptions& options,
                      std::vector<GapRegion>* candidates) {
  const std::size_t n1 = evaluated.size();
  // Merge runs of adjacent flagged bins (empty bins between them break a run).
  for (std::size_t k = 0; k < n1;) {
    if (!evaluated[k].flagged) {
      ++k;
      continue;
    }
    std::size_t end = k;
    BlockSums merged = sums[k];
    while (end + 1 < n1 && evaluated[end + 1].flagged) {
      ++end;
      Add(&merged, sums[end]);
    }
    if (end == k) {
      candidates->push_back(evaluated[k]);
    } else {
      GapRegion g = Evaluate(merged, boot, options);
      Describe(d, output, k, end, 0, &g);
      if (g.flagged) {
        candidates->push_back(g);
      } else {
        for (std::size_t j = k; j <= end; ++j) candidates->push_back(evaluated[j]);
      }
    }
    k = end + 1;
  }
}

}  // namespace

Localisation LocaliseGap(std::span<const std::int64_t> time_s, std::span<const double> residual,
                         const std::string& output, const std::vector<RegimeDriver>& drivers,
                         const LocaliseOptions& options) {
  Localisation result;
  const std::size_t n = std::min(time_s.size(), residual.size());
  int blocks = 0;
  const std::vector<int> block = AssignBlocks(time_s, residual, n, options.block_s, &blocks);
  if (blocks == 0) return result;
  const auto nb = static_cast<std::size_t>(blocks);
  auto empty_sums = [nb] {
    return BlockSums{std::vector<double>(nb), std::vector<double>(nb), std::vector<double>(nb)};
  };
  Bootstrap boot;
  boot.total = empty_sums();
  double total_abs = 0.0, total_rows = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (block[i] < 0) continue;
    const auto b = static_cast<std::size_t>(block[i]);
    boot.total.abs_error[b] += std::fabs(residual[i]);
    boot.total.rows[b] += 1.0;
    boot.total.residual[b] += residual[i];
    total_abs += std::fabs(residual[i]);
    total_rows += 1.0;
  }
  result.total_abs_error_w = total_abs / total_rows;
  std::mt19937_64 rng(options.seed);
  boot.draws.assign(static_cast<std::size_t>(options.bootstrap_samples), std::vector<int>(nb, 0));
  for (std::vector<int>& draw : boot.draws) {
    for (std::size_t k = 0; k < nb; ++k) ++draw[rng() % nb];
  }

  std::vector<GapRegion> candidates;
  for (const RegimeDriver& d : drivers) {
    const bool two_d = !d.name2.empty();
    const std::size_t n1 = d.edges.size() > 1 ? d.edges.size() - 1 : 0;
    const std::size_t n2 = two_d ? (d.edges2.size() > 1 ? d.edges2.size() - 1 : 0) : 1;
    if (n1 == 0 || n2 == 0) continue;
    std::vector<BlockSums> sums(n1 * n2, empty_sums());
    for (std::size_t i = 0; i < n && i < d.values.size(); ++i) {
      if (block[i] < 0) continue;
      const int k1 = BinOf(d.values[i], d.edges);
      const int k2 = two_d ? (i < d.values2.size() ? BinOf(d.values2[i], d.edges2) : -1) : 0;
      if (k1 < 0 || k2 < 0) continue;
      BlockSums& s = sums[static_cast<std::size_t>(k1) * n2 + static_cast<std::size_t>(k2)];
      const auto b = static_cast<std::size_t>(block[i]);
      s.abs_error[b] += std::fabs(residual[i]);
      s.rows[b] += 1.0;
      s.residual[b] += residual[i];
    }
    auto describe = [&](GapRegion* g, std::size_t k1_lo, std::size_t k1_hi, std::size_t k2) {
      Describe(d, output, k1_lo, k1_hi, k2, g);
    };
    std::vector<GapRegion> evaluated(n1 * n2);
    for (std::size_t k1 = 0; k1 < n1; ++k1) {
      for (std::size_t k2 = 0; k2 < n2; ++k2) {
        const BlockSums& s = sums[k1 * n2 + k2];
        GapRegion g = Evaluate(s, boot, options);
        describe(&g, k1, k1, k2);
        evaluated[k1 * n2 + k2] = g;
        if (g.rows > 0) result.bins.push_back(g);
      }
    }
    if (d.name == "day") {
      JudgeDays(options, &evaluated, &candidates, &result.bins);
      continue;
    }
    if (two_d) {
      for (const GapRegion& g : evaluated) {
        if (g.flagged) candidates.push_back(g);
      }
      continue;
    }
    MergeFlaggedRuns(d, output, sums, evaluated, boot, options, &candidates);
  }
  std::stable_sort(
      candidates.begin(), candidates.end(), [](const GapRegion& a, const GapRegion& b) {
        return a.share_of_abs_error - a.share_of_rows > b.share_of_abs_error - b.share_of_rows;
      });
  // At most two regions per driver, so that one strong regime (e.g. all of
  // the pump-on rows) does not crowd out the others (e.g. the days).
  std::map<std::string, int> per_driver;
  for (const GapRegion& g : candidates) {
    if (result.regions.size() >= options.max_regions) break;
    if (++per_driver[g.driver] > 2) continue;
    result.regions.push_back(g);
  }
  return result;
}

namespace {

// Hour of local mean solar time.
void AddHourOfDay(const Series& s, std::int64_t offset_s, std::vector<RegimeDriver>* out_) {
  const std::size_t n = s.size();
  RegimeDriver hour{"hour_of_day", std::vector<double>(n), {}, {}, {}, {}, {}};
  for (std::size_t i = 0; i < n; ++i) {
    const std::int64_t t = s.time_s[i];
    hour.values[i] = static_cast<double>(t - SolarDayStartS(t, offset_s)) / 3600.0;
  }
  for (int h = 0; h <= 24; h += 2) hour.edges.push_back(h);
  out_->push_back(std::move(hour));
}

// Local solar day (labelled by its date).
void AddSolarDay(const Series& s, std::int64_t offset_s, std::vector<RegimeDriver>* out_) {
  const std::size_t n = s.size();
  RegimeDriver day{"day", std::vector<double>(n), {}, {}, {}, {}, {}};
  std::int64_t last = std::numeric_limits<std::int64_t>::min();
  for (std::size_t i = 0; i < n; ++i) {
    const std::int64_t start = SolarDayStartS(s.time_s[i], offset_s);
    day.values[i] = static_cast<double>(start);
    if (start != last) {
      day.edges.push_back(static_cast<double>(start));
      day.labels.push_back(SolarDate(start, offset_s));
      last = start;
    }
  }
  day.edges.push_back(day.edges.back() + kSecondsPerDay);
  out_->push_back(std::move(day));
}

// Angle of incidence, measured when logged.
void AddAngleOfIncidence(const Series& s, const std::vector<SolarPosition>& sun, const Plant& plant,
                         std::vector<RegimeDriver>* out_) {
  const std::size_t n = s.size();
  RegimeDriver aoi{"aoi_deg", std::vector<double>(n, kNaN), {0, 15, 30, 45, 60, 75, 90}, {}, {}, {},
                   {}};
  for (std::size_t i = 0; i < n; ++i) {
    if (sun[i].elevation_rad <= 0.0) continue;
    const double measured = s.At(Channel::kAoiRad, i);
    aoi.values[i] = RadToDeg(std::isfinite(measured)
                                 ? measured
                                 : AngleOfIncidenceRad(sun[i].zenith_rad, sun[i].azimuth_rad,
                                                       plant.tilt_rad, plant.azimuth_rad));
  }
  out_->push_back(std::move(aoi));
}

// Rate of change of the in-plane irradiance, W/m² per minute.
void AddIrradianceRate(const Series& s, const std::vector<double>& g,
                       std::vector<RegimeDriver>* out_) {
  const std::size_t n = s.size();
  RegimeDriver rate{"g_poa_rate_w_m2_min",
                    std::vector<double>(n, kNaN),
                    {0, 5, 20, 50, 100, 200, kInf},
                    {},
                    {},
                    {},
                    {}};
  for (std::size_t i = 1; i < n; ++i) {
    const double dt_s = static_cast<double>(s.time_s[i] - s.time_s[i - 1]);
    if (dt_s > 0.0 && dt_s <= 2.0 * s.step_s) {
      rate.values[i] = std::fabs(g[i] - g[i - 1]) / (dt_s / 60.0);
    }
  }
  out_->push_back(std::move(rate));
}

// Beam fraction of the in-plane (or horizontal) irradiance.
void AddBeamFraction(const Series& s, std::vector<RegimeDriver>* out_) {
  const std::size_t n = s.size();
  RegimeDriver beam{"beam_fraction",
                    std::vector<double>(n, kNaN),
                    {0, 0.2, 0.4, 0.6, 0.8, 1.0001},
                    {},
                    {},
                    {},
                    {}};
  bool any = false;
  for (std::size_t i = 0; i < n; ++i) {
    double total = kNaN, diffuse = kNaN;
    if (s.Has(Channel::kGPoaDiffuseWM2) && s.Has(Channel::kGPoaWM2)) {
      total = s[Channel::kGPoaWM2][i];
      diffuse = s[Channel::kGPoaDiffuseWM2][i];
    } else if (s.Has(Channel::kGhiWM2) && s.Has(Channel::kDhiWM2)) {
      total = s[Channel::kGhiWM2][i];
      diffuse = s[Channel::kDhiWM2][i];
    }
    if (std::isfinite(total) && std::isfinite(diffuse) && total > 50.0) {
      beam.values[i] = std::clamp(1.0 - diffuse / total, 0.0, 1.0);
      any = true;
    }
  }
  if (any) out_->push_back(std::move(beam));
}

// Sky temperature deficit T_amb − T_sky, K (when the sky is measured).
void AddSkyDeficit(const Series& s, const Drivers& d, std::vector<RegimeDriver>* out_) {
  if (!(s.Has(Channel::kTSkyC) || s.Has(Channel::kLwDownWM2))) return;
  const std::size_t n = s.size();
  RegimeDriver sky{"sky_deficit_k",
                   std::vector<double>(n, kNaN),
                   {-kInf, 5, 10, 15, 20, 25, kInf},
                   {},
                   {},
                   {},
                   {}};
  for (std::size_t i = 0; i < n; ++i) {
    double t_sky_c = s.At(Channel::kTSkyC, i);
    const double lw = s.At(Channel::kLwDownWM2, i);
    if (!std::isfinite(t_sky_c) && std::isfinite(lw) && lw > 0.0) {
      t_sky_c = KToC(SkyTemperatureK(lw));
    }
    sky.values[i] = d.t_amb_c[i] - t_sky_c;
  }
  out_->push_back(std::move(sky));
}

// T_in − T_amb, K.
void AddInletMinusAmbient(const Drivers& d, std::vector<RegimeDriver>* out_) {
  const std::size_t n = d.size();
  RegimeDriver dt{"t_in_minus_t_amb_k",
                  std::vector<double>(n, kNaN),
                  {-kInf, -5, 0, 5, 10, 20, kInf},
                  {},
                  {},
                  {},
                  {}};
  for (std::size_t i = 0; i < n; ++i) dt.values[i] = d.t_in_c[i] - d.t_amb_c[i];
  out_->push_back(std::move(dt));
}

// Pump on/off, the flow level when running, and the minutes since the pump
// last switched.
void AddFlowDrivers(const Series& s, const Drivers& d, std::vector<RegimeDriver>* out_) {
  const std::size_t n = s.size();
  RegimeDriver on{"flow_on", std::vector<double>(n, kNaN), {0, 0.5, 1.5}, {"off", "on"}, {}, {},
                  {}};
  std::vector<double> running;
  for (std::size_t i = 0; i < n; ++i) {
    const double m = d.mdot_kg_s[i];
    if (!std::isfinite(m)) continue;
    on.values[i] = m > 0.0 ? 1.0 : 0.0;
    if (m > 0.0) running.push_back(m);
  }
  out_->push_back(std::move(on));
  if (running.size() >= 50) {
    std::sort(running.begin(), running.end());
    RegimeDriver level{"flow_kg_s", std::vector<double>(n, kNaN), {}, {}, {}, {}, {}};
    level.edges.push_back(running.front());
    for (int q = 1; q < 5; ++q) {
      const double v = running[running.size() * static_cast<std::size_t>(q) / 5];
      if (v > level.edges.back()) level.edges.push_back(v);
    }
    level.edges.push_back(std::nextafter(running.back(), kInf));
    for (std::size_t i = 0; i < n; ++i) {
      if (d.mdot_kg_s[i] > 0.0) level.values[i] = d.mdot_kg_s[i];
    }
    if (level.edges.size() >= 3) out_->push_back(std::move(level));
  }
  RegimeDriver since{
      "min_since_pump_switch", std::vector<double>(n, kNaN), {0, 5, 15, 60, kInf}, {}, {}, {}, {}};
  double last_switch_s = kNaN;
  for (std::size_t i = 0; i < n; ++i) {
    const double m = d.mdot_kg_s[i];
    if (i > 0 && std::isfinite(m) && std::isfinite(d.mdot_kg_s[i - 1]) &&
        (m > 0.0) != (d.mdot_kg_s[i - 1] > 0.0)) {
      last_switch_s = static_cast<double>(s.time_s[i]);
    }
    if (std::isfinite(last_switch_s)) {
      since.values[i] = (static_cast<double>(s.time_s[i]) - last_switch_s) / 60.0;
    }
  }
  out_->push_back(std::move(since));
}

// Sun azimuth × elevation cells (sun up).
void AddSunCells(const std::vector<SolarPosition>& sun, std::vector<RegimeDriver>* out_) {
  const std::size_t n = sun.size();
  RegimeDriver cells{"sun_azimuth_deg",
                     std::vector<double>(n, kNaN),
                     {},
                     {},
                     "sun_elevation_deg",
                     std::vector<double>(n, kNaN),
                     {0, 10, 20, 30, 45, 60, 90}};
  for (int a = 0; a <= 360; a += 30) cells.edges.push_back(a);
  for (std::size_t i = 0; i < n; ++i) {
    if (sun[i].elevation_rad <= 0.0) continue;
    cells.values[i] = RadToDeg(sun[i].azimuth_rad);
    cells.values2[i] = RadToDeg(sun[i].elevation_rad);
  }
  out_->push_back(std::move(cells));
}

}  // namespace

std::vector<RegimeDriver> StandardRegimeDrivers(const Series& s, const Drivers& d,
                                                const Plant& plant) {
  std::vector<RegimeDriver> out;
  const std::size_t n = s.size();
  if (n == 0) return out;
  const std::int64_t offset_s = SolarDayOffsetS(plant);

  AddHourOfDay(s, offset_s, &out);
  AddSolarDay(s, offset_s, &out);

  // Sun position at the middle of each row.
  const std::vector<SolarPosition> sun = SunAtRowMiddles(s, plant);

  AddAngleOfIncidence(s, sun, plant, &out);
  const std::vector<double>& g = d.g_poa_w_m2;
  out.push_back({"g_poa_w_m2", g, {0, 50, 200, 400, 600, 800, 1000, 1500}, {}, {}, {}, {}});
  AddIrradianceRate(s, g, &out);
  AddBeamFraction(s, &out);
  if (s.Has(Channel::kWindMS)) {
    out.push_back({"wind_m_s", s[Channel::kWindMS], {0, 1, 2, 3, 4, 6, 10, kInf}, {}, {}, {}, {}});
  }
  AddSkyDeficit(s, d, &out);
  AddInletMinusAmbient(d, &out);
  AddFlowDrivers(s, d, &out);
  AddSunCells(sun, &out);
  return out;
}

}  // namespace pvtwin
