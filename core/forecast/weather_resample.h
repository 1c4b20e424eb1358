// A weather forecast as a provider gives it (hourly or 15-min values) brought
// to the 1-min rows of table weather_forecast (issue 15), without inventing
// energy:
//
//   irradiance   each provider value is the mean over its interval; the
//                interval's clear-sky index k = value / mean(clear sky over
//                the interval's minutes) times each minute's clear sky
//                gives the minute, so the minutes' mean is the value
//                exactly. Clear sky: Ineichen & Perez (core/physics/
//                clear_sky.h) at the middle of each minute; the in-plane
//                value (GTI) takes the clear sky transposed to the plane as
//                its shape, GHI and DHI the clear-sky GHI (so DHI ≤ GHI
//                holds in every minute when it holds for the interval).
//                Where the interval's clear sky is below
//                min_clear_sky_mean_w_m2 or k would exceed
//                max_clear_sky_index (sunrise and sunset hours that the
//                provider's and our sun disagree on), the value is spread
//                evenly over the interval's minutes with the sun above the
//                horizon (over all of them if none): also exact in energy.
//                No minute exceeds its bound: the physical limit of the
//                channel (core/data/physical_limits.h) and
//                max_clear_sky_index × the minute's clear sky +
//                clear_sky_allowance_w_m2 (the plane's bound takes the larger
//                of its clear sky and the clear-sky GHI, as the diffuse on a
//                plane the sun is behind can reach the horizontal's). A
//                minute above is lowered to its bound and what it loses goes
//                to the interval's other minutes below theirs (daylight ones
//                when it has daylight), so the interval keeps its energy
//                whenever the bounds can hold it. An interval carrying more
//                than that (value > the mean of its minutes' bounds) is
//                physically impossible where it is: mostly a file in local
//                time labelled UTC, or stamps shifted by hours. It is stored
//                at its bounds and listed in the summary (above_clear_sky),
//                for a warning and for the rows' source (kAboveClearSkyMark).
//                The index path (k ≤ max_clear_sky_index) never exceeds the
//                bound, so a physical forecast keeps every value.
//                Without GTI, g_poa_w_m2 (and g_poa_diffuse_w_m2) are GHI/DHI
//                transposed with the model's isotropic sky (paper 2.5,
//                core/physics/irradiance.h), capped at the plane's bound
//                (1/cos θ_z near the horizon turns a few W/m² of horizontal
//                beam into thousands on the plane). DHI missing but DNI given:
//                DHI = GHI − DNI·mean cos θ_z over the interval, within
//                [0, GHI].
//   temperature, linear between the provider's time stamps, taken at each
//   wind         minute's middle; held for up to one provider step beyond
//                the first and last stamp. Wind is brought from the
//                provider's height (10 m) to the collector's height by the
//                power law v(z) = v_ref·(z/z_ref)^α, α = 1/7
//                (core/physics/wind.h).
//   long-wave    as given (t_sky_c or lw_down_w_m2, the other derived with
//                T_sky = (L/σ)^(1/4)); else, with air temperature, dew point
//                or relative humidity, and cloud cover: Brunt's clear-sky
//                emissivity with the cloud correction of Crawford & Duchon
//                on the collector plane (core/physics/sky_radiation.h).
//
// Time convention: output rows start at whole minutes and are means over
// [ts, ts + 60) like measurement_1min; the input's conventions are fields of
// ProviderWeather.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/common/plant.h"
#include "core/common/series.h"

namespace pvtwin {

struct ProviderWeather {
  // Provider time stamps (unix s UTC), strictly increasing, step_s apart,
  // whole minutes.
  std::vector<std::int64_t> time_s;
  double step_s = 3600.0;
  // The irradiance value at stamp t is the mean over
  // [t + irradiance_offset_s, t + irradiance_offset_s + step_s): −step_s for
  // Open-Meteo (the preceding interval), 0 for the canonical CSV (time marks
  // the interval's start).
  double irradiance_offset_s = -3600.0;
  // Instantaneous values stand for the moment t + instant_offset_s
  // (Open-Meteo: 0; the canonical CSV's interval means: step_s / 2).
  double instant_offset_s = 0.0;
  // Channels, one value per stamp: an empty vector is a channel the
  // provider did not give, NaN a missing value.
  std::vector<double> gti_w_m2, ghi_w_m2, dhi_w_m2, dni_w_m2;  // interval means, W/m²
  std::vector<double> t_amb_c;                                 // °C
  std::vector<double> wind_m_s;                                // m/s at wind_height_m
  std::vector<double> dew_point_c;                             // °C
  std::vector<double> relative_humidity_pct;                   // %, 0 … 100
  std::vector<double> cloud_cover_pct;                         // %, 0 … 100
  std::vector<double> t_sky_c, lw_down_w_m2;                   // long-wave, when given
  double wind_height_m = 10.0;                                 // z_ref of wind_m_s
};

// The minutes [begin, end) and, per minute (at its middle), the sun and the
// clear sky of Ineichen & Perez (core/physics/clear_sky.h): horizontal and
// transposed to the collector plane with the model's isotropic sky. The
// reference of a clear-sky index (the resampling below, the forecast's
// smart persistence).
struct ClearSkyGrid {
  std::vector<std::int64_t> time_s;  // minute starts
  std::vector<double> zenith_rad, aoi_rad;
  std::vector<double> clear_ghi_w_m2, clear_dhi_w_m2, clear_poa_w_m2;
};
ClearSkyGrid MakeClearSkyGrid(const Plant& plant, std::int64_t begin, std::int64_t end,
                              double linke_turbidity);

struct WeatherResampleOptions {
  double collector_height_m = 10.0;    // z of the wind the model wants, m
  double hellmann_exponent = 1.0 / 7;  // α of the power law
  double linke_turbidity = 3.0;        // of the clear-sky shape (a typical rural value)
  double min_clear_sky_mean_w_m2 = 5.0;
  // The largest clear-sky index a minute can have, against the clear sky
  // above (T_L = 3). Cloud enhancement lifts 1-min irradiance to about 1.5×
  // the clear sky (Yordanov et al. 2013, IEEE J. Photovoltaics 3(1):271,
  // "over 1.5 times"; bursts last seconds to minutes); the cleanest air
  // (T_L = 2) gives exp(c2·AM) times the T_L = 3 clear GHI at sea level by
  // the Ineichen & Perez formula (core/physics/clear_sky.h): 1.08 at air
  // mass 2, 1.21 at air mass 5, so 1.5 · 1.21 = 1.8 < 2; lower suns, where
  // the factor grows, are covered by the allowance below.
  double max_clear_sky_index = 2.0;
  // Added to each minute's bound: at low sun the clear sky of a minute is a
  // few W/m² and the provider's sun and ours differ by minutes. 50 W/m² is
  // the additive term of the BSRN "extremely rare" GHI limit
  // 1.2·S_a·cos(θz)^1.2 + 50 W/m² (Long & Dutton, BSRN recommended QC
  // tests), which has the same purpose.
  double clear_sky_allowance_w_m2 = 50.0;
};

// An irradiance interval of the provider carrying more than its minutes can
// hold (see the header): physically impossible at that time.
struct IrradianceAboveClearSky {
  Channel channel = Channel::kGhiWM2;
  std::int64_t from_s = 0, to_s = 0;  // the interval [from_s, to_s)
  double value_w_m2 = 0.0;            // the provider's mean over it
  double clear_sky_w_m2 = 0.0;        // the clear sky's mean over it
  double bound_w_m2 = 0.0;            // the bounds' mean: what was stored
};

// Appended to weather_forecast.source for the rows of the minutes of an
// interval above its clear sky (import-weather, the daemon's fetch), and what
// a forecast driven by such rows says in its inputs (core/forecast/
// forecast.h).
inline constexpr std::string_view kAboveClearSkyMark = " [clipped: irradiance above clear sky]";
inline constexpr std::string_view kAboveClearSkyInputs =
    "weather_warning=irradiance_above_clear_sky";

struct WeatherResampleSummary {
  std::size_t rows = 0;
  std::size_t irradiance_intervals = 0;
  std::size_t flat_intervals = 0;  // spread evenly over their daylight minutes (see above)
  double wind_factor = 1.0;        // (z / z_ref)^α applied to the wind
  // Where each written channel came from, e.g. "g_poa_w_m2 from GHI/DHI
  // (isotropic sky)", in channel order.
  std::vector<std::string> origins;
  // Intervals above their clear sky, in channel and time order; per output
  // row 1 where the row lies in one of them (empty when there is none).
  std::vector<IrradianceAboveClearSky> above_clear_sky;
  std::vector<std::uint8_t> above_clear_sky_rows;
  // Minutes of g_poa_w_m2 transposed from GHI/DHI that were lowered to the
  // plane's bound.
  std::size_t capped_poa_minutes = 0;
  // Cells outside the physical limits after resampling (long-wave and
  // temperatures from the sky model, wind): made missing.
  std::size_t outside_limits = 0;
};

// Rows of whole minutes covering every irradiance interval (or, without
// irradiance, the instantaneous stamps), with the channels of table
// weather_forecast that the input allows: g_poa_w_m2, ghi_w_m2, dhi_w_m2,
// g_poa_diffuse_w_m2, t_amb_c, wind_m_s, t_sky_c, lw_down_w_m2. False and
// *error for inconsistent input (lengths, steps, order): a caller bug or a
// file the I/O layer should have refused.
bool ResampleWeatherTo1Min(const Plant& plant, const ProviderWeather& in,
                           const WeatherResampleOptions& options, Series* out,
                           WeatherResampleSummary* summary, std::string* error);

}  // namespace pvtwin
