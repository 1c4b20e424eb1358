// Physical limits of the canonical channels: one table, applied once on each
// path at the edge where data enter pvtwin, so that the fits never see a
// value no sensor can deliver (−300 °C, 1e308 W, negative wind, an angle of
// incidence of 500°). A value outside its channel's limits is treated as
// missing, and the reader that can name file, line and column says so.
// The edges:
//  * live data: the Modbus poller's QC (io/modbus/modbus_poller.cc; `pvtwin
//    poll --once` says why it rejects, io/modbus/modbus_read_once.cc);
//  * files: the CSV reader (io/files/csv.cc);
//  * rows in the store that other programs may have written: the store's
//    reads of 1-min rows, interval rows and forecast inputs (io/store/), and
//    of 5 s samples through the 1-min aggregation (core/data/aggregate.cc);
//  * provider weather: the resampling to 1-min rows (core/forecast/
//    weather_resample.cc), where interpolation, transposition and the wind's
//    height correction make new channel values (the provider's file,
//    io/weather/weather_file.cc, is read against bounds of its own
//    variables first: hourly means at 2 m and 10 m, not yet channels).
// Stages after an edge trust what came in.
//
// The limits are wide on purpose: they catch broken readings, not unusual
// weather. Sources:
//  * short-wave irradiance: BSRN "physically possible" upper limit
//    (Long & Dutton, BSRN Global Network recommended QC tests, V2.0):
//    1.5·S_a·cos(θz)^1.2 + 100 W/m² ≤ 2150 W/m² for GHI; 2000 W/m² in the
//    collector plane with cloud enhancement is already rare, 2500 W/m² is
//    not reached. The lower limit −30 W/m² is the largest night-time
//    thermal offset a pyranometer may show: ISO 9060's zero off-set a)
//    (the response to 200 W/m² net thermal radiation) is at most ±7 W/m²
//    for a secondary standard, ±15 W/m² for a first-class and ±30 W/m² for
//    a second-class instrument (the WMO/ISO 9060:1990 classification table,
//    reprinted e.g. in the Kipp & Zonen CM 11 manual, appendix I; ISO
//    9060:2018's classes A, B, C roughly correspond to these three). Night
//    rows keep their small negative readings as logged; a reading below
//    −30 W/m² is no offset but a broken sensor or a wrong scale.
//  * long-wave irradiance: BSRN physically possible limits 40–700 W/m².
//  * air temperature: −90 … 60 °C (the recorded extremes are −89.2 °C and
//    56.7 °C); sky temperature −120 … 60 °C.
//  * fluid and collector temperatures: −60 … 250 °C (brine of a heat-pump
//    source down to about −25 °C; stagnation of a glazed collector about
//    200 °C).
//  * wind speed 0 … 100 m/s; angle of incidence 0 … 180°.
//  * specific quantities scale with the collector area A: flow |ṁ| ≤
//    1 kg/(s·m²) (50× the nominal 0.02 kg/(s·m²)); P_el −50 … 600 W/m²;
//    Q_u −5000 … 2500 W/m² (night losses of a hot collector reach a few
//    kW/m² only at stagnation temperatures).
// Small negative flows (a stopped pump's meter) are the paper's correction
// (core/data/qc.h), applied after these limits.
#pragma once

#include <array>
#include <cstddef>

#include "core/common/channels.h"
#include "core/common/series.h"

namespace pvtwin {

struct PhysicalLimit {
  double lo = 0.0;  // in the channel's unit as core holds it (aoi in rad; the
                    // readers convert at the edge, io/files/csv.h's DescribeCsvLimit)
  double hi = 0.0;
  bool Contains(double x) const { return x >= lo && x <= hi; }
};

// Area used for the area-scaled limits when the plant's is unknown (the
// config's upper bound of area_m2).
inline constexpr double kMaxAreaM2 = 1e6;

// The limits of channel c for a field of area_m2 (≤ 0: unknown, kMaxAreaM2).
PhysicalLimit PhysicalLimitOf(Channel c, double area_m2);

// Whether a reading of channel c passes an edge (the Modbus poller, `pvtwin
// poll --once`, the CSV reader): inside its limits, or a short-wave
// irradiance that is the paper's night glitch (core/data/qc.h), which passes
// as read so that ApplyPaperCorrections sets it to 0 after the edge on every
// path alike (the CSV import, the 1-min aggregation of polled samples).
bool PassesEdge(Channel c, double value, double area_m2);

// A forecast provider's values before they are channels (read by
// io/weather/weather_file.cc): hourly or 15-min values of the provider's own
// variables, in pvtwin's units.
enum class ProviderQuantity {
  kAirTemperatureC,  // temperature_2m, dew_point_2m: the air temperature's limits
  kPercent,          // relative_humidity_2m, cloud_cover: 0 … 100 %
  kWindAt10mMS,      // wind_speed_10m: 0 … 113 m/s, the strongest gust recorded
                     // (113 m/s, Barrow Island, 10 April 1996; WMO archive)
  kIrradianceWM2,    // the short-wave variables: 0 … 1500 W/m² (BSRN's physically
                     // possible bound for GHI near 1400 W/m²)
};

PhysicalLimit ProviderLimitOf(ProviderQuantity q);

// What ApplyPhysicalLimits changed, per channel.
struct LimitViolations {
  std::array<std::size_t, kNumChannels> count{};
  std::array<std::size_t, kNumChannels> first_row{};
  std::array<double, kNumChannels> first_value{};

  std::size_t Total() const;
};

// Sets every finite cell outside its channel's limits to NaN (missing).
LimitViolations ApplyPhysicalLimits(Series* series, double area_m2);

}  // namespace pvtwin
