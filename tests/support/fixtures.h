// Times and paths that many tests share. One definition each, so that test
// files can be compiled together in one translation unit (CMake's unity
// build, tests/CMakeLists.txt) without two files defining the same name.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace pvtwin::testing {

inline constexpr std::int64_t kDayS = 86400;

// 2024-06-01 00:00 UTC: a start for series whose rows need the sun. The 'I'
// variants weight the beam with the IAM at its angle of incidence, computed
// from the plant's site and the row times unless an aoi_deg column is given.
inline constexpr std::int64_t kJune1_2024UtcS = 1717200000;
// 2024-06-01 12:00 UTC, a multiple of 60.
inline constexpr std::int64_t kJune1Noon2024UtcS = kJune1_2024UtcS + 12 * 3600;
// 2024-06-20 00:00 UTC, the solstice's day.
inline constexpr std::int64_t kJune20_2024UtcS = 1718841600;

// The example plant's truth (config/examples/sim-plant.toml) and the model
// its daemon fits.
inline constexpr const char* kExamplePlantTruth = "2N2CrI+wind+transport_delay";
inline constexpr const char* kExampleDaemonModel = "2N1Ccolwr";

#ifdef PVTWIN_DATA_DIR
// The real htw saar days (tests/data/htwsaar-pvt).
inline const std::filesystem::path kHtwSaarDir =
    std::filesystem::path(PVTWIN_DATA_DIR) / "htwsaar-pvt";
// A file of that folder, quoted for a command line.
inline std::string HtwSaarArg(const std::string& name) {
  return "'" + (kHtwSaarDir / name).string() + "'";
}
#endif

#ifdef PVTWIN_SOURCE_DIR
// The example plant (config/examples/sim-plant.toml).
inline const std::filesystem::path kExamplePlantConfig =
    std::filesystem::path(PVTWIN_SOURCE_DIR) / "config" / "examples" / "sim-plant.toml";
#endif

}  // namespace pvtwin::testing
