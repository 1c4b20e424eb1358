#include "daemon/service/store_cli.h"

#include <iostream>

namespace pvtwin::cli {

StoreOptions StoreOptionsFor(const Config& config) {
  StoreOptions options;
  options.aggregate.sample_period_s = config.poll.period_s;
  options.aggregate.fluid_cp_j_kgk = config.plant.fluid_cp_j_kgk;
  options.aggregate.area_m2 = config.plant.area_m2;
  options.time_zone = config.calibration.timezone;
  return options;
}

bool OpenStoreOrReport(const std::string& path, const StoreOptions& options,
                       std::unique_ptr<Store>* store) {
  std::string error;
  *store = Store::Open(path, options, &error);
  if (*store != nullptr) return true;
  std::cerr << error << "\n";
  return false;
}

bool OpenStoreReadOnlyOrReport(const std::string& path, const StoreOptions& options,
                               std::unique_ptr<Store>* store) {
  std::string error;
  *store = Store::OpenReadOnly(path, options, &error);
  if (*store != nullptr) return true;
  std::cerr << error << "\n";
  return false;
}

}  // namespace pvtwin::cli
