#include "core/irradiance_drivers.h"

#include <cmath>

namespace pvtwin {

void ComputeIrradianceDrivers(const Series& s, const Plant& plant, const ModelSpec& spec,
                              std::vector<double>* g_poa_w_m2, std::vector<double>* g_abs_w_m2) {
  (void)plant;
  (void)spec;
  *g_poa_w_m2 = s[Channel::kGPoaWM2];
  *g_abs_w_m2 = *g_poa_w_m2;
}

}  // namespace pvtwin
