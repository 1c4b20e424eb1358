// ISO 9806 quasi-dynamic equivalents of identified grey-box parameters, so
// that a calibration can be compared with a collector's datasheet (Solar
// Keymark). ISO 9806:2017's quasi-dynamic power equation, per m² of gross
// area:
//   Q/A = η0·G − c1·(ϑm − ϑa) − c2·(ϑm − ϑa)² − c3·u·(ϑm − ϑa)
//         + c4·(E_L − σ·Ta⁴) − c6·u·G − c5·dϑm/dt        (IAM terms at normal incidence)
// The grey-box model is run to its steady state at constant conditions and
// the coefficients are read off by finite differences, at a reference wind
// speed u_ref (the model's wind laws are not linear in u; the paper's 'w'
// form even lowers the front loss with wind, so an extrapolation to u = 0
// would say little):
//   η0(u_ref), (c1 + c3·u_ref)  from two mean fluid temperatures
//           ϑm = (ϑin + ϑout)/2 at G = 1000 W/m² of beam at normal incidence;
//   c3, c6  the local slopes −dη0/du and d(c1 + c3·u)/du between u_ref ± 1 m/s
//           (0 for a model without wind dependence);
//   c4      from the sky long-wave E_L = σ·T_sky⁴ at ambient and 10 K below
//           it, at ϑm ≈ ϑa (0 for a model without sky radiation).
// c2 and c5 are not read off: the model's losses are linear in ϑm − ϑa, and
// c5 is the heat capacity, which the model has per node (reported as such).
// Ambient 25 °C, flow fluid_flow_kg_s (the data's median when pumping).
#pragma once

#include "core/common/params.h"
#include "core/common/plant.h"
#include "core/model/variant.h"

namespace pvtwin {

struct Iso9806Equivalents {
  double u_ref_m_s = 3.0;   // wind speed of eta0 and loss_w_m2k
  double eta0 = 0.0;        // zero-loss efficiency at u_ref, −
  double loss_w_m2k = 0.0;  // heat loss coefficient c1 + c3·u at u_ref, W/(m²K)
  double c3_j_m3k = 0.0;    // wind dependence of the heat loss, J/(m³K)
  double c4 = 0.0;          // long-wave irradiance dependence, −
  double c6_s_m = 0.0;      // wind dependence of the zero-loss efficiency, s/m
  double c5_j_m2k = 0.0;    // effective heat capacity (sum of the node capacities), J/(m²K)
  bool ok = false;          // false when the model gave no steady state
};

Iso9806Equivalents Iso9806EquivalentsOf(const Plant& plant, const ModelSpec& spec,
                                        const ParamVector& params, double fluid_flow_kg_s,
                                        double u_ref_m_s = 3.0);

}  // namespace pvtwin
