#include "core/fit/iso9806.h"

#include <algorithm>
#include <cmath>

#include "core/common/series.h"
#include "core/common/units.h"
#include "core/model/thermal_model.h"

namespace pvtwin {

namespace {

constexpr double kGWM2 = 1000.0;
constexpr double kTAmbC = 25.0;
constexpr double kSigma = 5.670374419e-8;  // Stefan–Boltzmann, W/(m²K⁴)

struct Point {
  double eta = 0.0;     // Q_u/(A·G)
  double dt_m_k = 0.0;  // ϑm − ϑa
  bool ok = false;
};

// Steady state at constant inputs: 12 h at 15 min, the last row.
Point SteadyState(const Plant& plant, const ModelSpec& spec, const ParamVector& params,
                  double mdot_kg_s, double t_in_c, double wind_m_s, double t_sky_c) {
  constexpr std::size_t kRows = 48;
  Series s;
  s.step_s = 900.0;
  for (std::size_t i = 0; i < kRows; ++i)
    s.time_s.push_back(1717200000 + 900 * static_cast<std::int64_t>(i));
  const auto fill = [&s](Channel c, double v) { s[c].assign(kRows, v); };
  fill(Channel::kTInC, t_in_c);
  fill(Channel::kMdotKgS, mdot_kg_s);
  fill(Channel::kGPoaWM2, kGWM2);
  fill(Channel::kGPoaDiffuseWM2, 0.0);  // all beam,
  fill(Channel::kAoiRad, 0.0);          // at normal incidence
  fill(Channel::kTAmbC, kTAmbC);
  fill(Channel::kTBackC, kTAmbC);
  fill(Channel::kWindMS, wind_m_s);
  fill(Channel::kTSkyC, t_sky_c);
  fill(Channel::kValid, 1.0);
  Drivers drivers;
  std::string error;
  Point p;
  if (!PrepareDrivers(s, plant, spec, &drivers, &error)) return p;
  SimOutputs out;
  Simulate(drivers, params, &out);
  const std::size_t last = kRows - 1;
  p.eta = out.q_th_w[last] / (plant.area_m2 * kGWM2);
  p.dt_m_k = 0.5 * (t_in_c + out.t_out_c[last]) - kTAmbC;
  p.ok = std::isfinite(p.eta) && std::isfinite(p.dt_m_k);
  return p;
}

// η0(u) and the loss coefficient c1 + c3·u at wind u: the straight line
// through two mean fluid temperatures.
struct Line {
  double eta0 = 0.0, loss_w_m2k = 0.0;
  bool ok = false;
};

Line LineAtWind(const Plant& plant, const ModelSpec& spec, const ParamVector& params,
                double mdot_kg_s, double wind_m_s) {
  const Point a = SteadyState(plant, spec, params, mdot_kg_s, kTAmbC - 5.0, wind_m_s, kTAmbC);
  const Point b = SteadyState(plant, spec, params, mdot_kg_s, kTAmbC + 20.0, wind_m_s, kTAmbC);
  Line line;
  if (!a.ok || !b.ok || std::abs(b.dt_m_k - a.dt_m_k) < 1e-6) return line;
  // η = η0 − loss·(ϑm − ϑa)/G
  const double slope = (b.eta - a.eta) / ((b.dt_m_k - a.dt_m_k) / kGWM2);
  line.loss_w_m2k = -slope;
  line.eta0 = a.eta - slope * a.dt_m_k / kGWM2;
  line.ok = true;
  return line;
}

}  // namespace

Iso9806Equivalents Iso9806EquivalentsOf(const Plant& plant, const ModelSpec& spec,
                                        const ParamVector& params, double fluid_flow_kg_s,
                                        double u_ref_m_s) {
  Iso9806Equivalents iso;
  iso.u_ref_m_s = u_ref_m_s;
  const double u_lo_m_s = std::max(0.0, u_ref_m_s - 1.0), u_hi_m_s = u_ref_m_s + 1.0;
  const Line ref = LineAtWind(plant, spec, params, fluid_flow_kg_s, u_ref_m_s);
  const Line lo = LineAtWind(plant, spec, params, fluid_flow_kg_s, u_lo_m_s);
  const Line hi = LineAtWind(plant, spec, params, fluid_flow_kg_s, u_hi_m_s);
  if (!ref.ok || !lo.ok || !hi.ok) return iso;
  iso.eta0 = ref.eta0;
  iso.loss_w_m2k = ref.loss_w_m2k;
  iso.c6_s_m = -(hi.eta0 - lo.eta0) / (u_hi_m_s - u_lo_m_s);
  iso.c3_j_m3k = (hi.loss_w_m2k - lo.loss_w_m2k) / (u_hi_m_s - u_lo_m_s);
  // c4: E_L − σTa⁴ from the sky at ambient to 10 K below it, at ϑin = ϑa.
  const Point warm = SteadyState(plant, spec, params, fluid_flow_kg_s, kTAmbC, u_ref_m_s, kTAmbC);
  const Point cold =
      SteadyState(plant, spec, params, fluid_flow_kg_s, kTAmbC, u_ref_m_s, kTAmbC - 10.0);
  const double t_a_k = kTAmbC + kZeroCelsiusK;
  const double t_sky_k = kTAmbC - 10.0 + kZeroCelsiusK;
  const double delta_e_w_m2 = kSigma * (std::pow(t_sky_k, 4) - std::pow(t_a_k, 4));
  if (!warm.ok || !cold.ok) return iso;
  // Q/A difference at (nearly) the same ϑm, corrected for the small change
  // of ϑm with the loss line.
  const double dq_w_m2 =
      (cold.eta - warm.eta) * kGWM2 + ref.loss_w_m2k * (cold.dt_m_k - warm.dt_m_k);
  iso.c4 = dq_w_m2 / delta_e_w_m2;
  iso.c5_j_m2k = params[static_cast<std::size_t>(Param::kCPvJM2K)] * (spec.c_pv ? 1.0 : 0.0) +
                 params[static_cast<std::size_t>(Param::kCCollJM2K)] * (spec.c_coll ? 1.0 : 0.0);
  iso.ok = std::isfinite(iso.eta0) && std::isfinite(iso.loss_w_m2k) && std::isfinite(iso.c4);
  return iso;
}

}  // namespace pvtwin
