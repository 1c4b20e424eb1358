#include "core/synth/absorber_sensor.h"

#include <algorithm>
#include <cmath>

#include "core/common/units.h"

namespace pvtwin {
namespace {

// The linear network of the header: source S, loss U_L to ambient, flow
// coupling k_f to the inlet (per m²).
struct AbsorberBalance {
  double source_w_m2 = 0.0;
  double u_loss_w_m2k = 0.0;
  double k_flow_w_m2k = 0.0;
};

AbsorberBalance BalanceOf(const AbsorberSensorParams& p, const AbsorberSensorInput& in) {
  const double t_amb_k = CToK(in.t_amb_c);
  const double black_body_w_m2 = kStefanBoltzmannW_m2k4 * std::pow(t_amb_k, 4);
  const double u_rad_w_m2k = 4.0 * p.eps_lw * kStefanBoltzmannW_m2k4 * std::pow(t_amb_k, 3);
  AbsorberBalance b;
  b.source_w_m2 = p.absorbed_fraction * std::max(0.0, in.g_poa_w_m2) +
                  p.eps_lw * (in.lw_down_w_m2 - black_body_w_m2);
  b.u_loss_w_m2k = p.u_front_w_m2k +
                   p.u_wind_w_m2k * std::pow(std::max(0.0, in.wind_m_s), p.n_wind) +
                   p.u_back_w_m2k + u_rad_w_m2k;
  if (in.mdot_kg_s > 0.0) {
    const double capacity_w_m2k = in.mdot_kg_s * in.fluid_cp_j_kgk / in.area_m2;
    b.k_flow_w_m2k =
        1.0 / (p.r_internal_m2k_w + p.r0_fluid_m2k_w + p.r1_fluid / (2.0 * capacity_w_m2k));
  }
  return b;
}

double SteadyStateC(const AbsorberBalance& b, const AbsorberSensorInput& in) {
  return (b.source_w_m2 + b.u_loss_w_m2k * in.t_amb_c + b.k_flow_w_m2k * in.t_in_c) /
         (b.u_loss_w_m2k + b.k_flow_w_m2k);
}

}  // namespace

double AbsorberSteadyStateC(const AbsorberSensorParams& params, const AbsorberSensorInput& in) {
  return SteadyStateC(BalanceOf(params, in), in);
}

AbsorberSensorOutput StepAbsorberSensor(const AbsorberSensorParams& params,
                                        const AbsorberSensorInput& in, double t_abs_c) {
  const AbsorberBalance b = BalanceOf(params, in);
  const double t_steady_c = SteadyStateC(b, in);
  const double tau_s = params.c_j_m2k / (b.u_loss_w_m2k + b.k_flow_w_m2k);
  AbsorberSensorOutput out;
  out.t_abs_c = t_steady_c + (t_abs_c - t_steady_c) * std::exp(-in.dt_s / tau_s);
  out.q_u_w = b.k_flow_w_m2k * (out.t_abs_c - in.t_in_c) * in.area_m2;
  return out;
}

}  // namespace pvtwin
