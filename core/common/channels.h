// The canonical measurement channels of pvtwin (doc/contracts.md, "Canonical CSV").
// One table names every channel once; the CSV reader, the SQLite store and the
// Modbus register map all refer to it, so a channel is spelled the same
// everywhere.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string_view>

namespace pvtwin {

enum class Channel : std::size_t {
  kTInC,            // fluid inlet temperature, °C
  kTOutC,           // fluid outlet temperature, °C
  kMdotKgS,         // fluid mass flow, kg/s (CSV: flow_kg_s, or flow_l_h converted)
  kGPoaWM2,         // global irradiance in the collector plane, W/m²
  kGhiWM2,          // global horizontal irradiance, W/m²
  kDhiWM2,          // diffuse horizontal irradiance, W/m²
  kGPoaDiffuseWM2,  // diffuse irradiance in the collector plane, W/m²
  kAoiRad,          // angle of incidence of beam radiation, rad (CSV: aoi_deg)
  kTAmbC,           // ambient air temperature, °C
  kWindMS,          // wind speed, m/s
  kTSkyC,           // equivalent sky temperature, °C
  kLwDownWM2,       // long-wave irradiance on the collector plane, W/m²
  kTBackC,          // temperature behind the collector, °C
  kTPvC,            // measured PV cell / absorber temperature, °C
  kPElW,            // electrical power, W
  kQThW,            // useful thermal power, W
  kValid,           // 1 = row counts in objective and errors, 0 = simulate only
  kCount
};

inline constexpr std::size_t kNumChannels = static_cast<std::size_t>(Channel::kCount);

struct ChannelInfo {
  Channel channel;
  std::string_view name;  // canonical CSV / SQL column name
  std::string_view unit;
};

// Column names as in doc/contracts.md. kMdotKgS and kAoiRad are stored in SI/radians;
// their CSV spellings are flow_kg_s and aoi_deg (converted at the I/O edge).
inline constexpr std::array<ChannelInfo, kNumChannels> kChannels = {{
    {Channel::kTInC, "t_in_c", "°C"},
    {Channel::kTOutC, "t_out_c", "°C"},
    {Channel::kMdotKgS, "flow_kg_s", "kg/s"},
    {Channel::kGPoaWM2, "g_poa_w_m2", "W/m²"},
    {Channel::kGhiWM2, "ghi_w_m2", "W/m²"},
    {Channel::kDhiWM2, "dhi_w_m2", "W/m²"},
    {Channel::kGPoaDiffuseWM2, "g_poa_diffuse_w_m2", "W/m²"},
    {Channel::kAoiRad, "aoi_deg", "°"},
    {Channel::kTAmbC, "t_amb_c", "°C"},
    {Channel::kWindMS, "wind_m_s", "m/s"},
    {Channel::kTSkyC, "t_sky_c", "°C"},
    {Channel::kLwDownWM2, "lw_down_w_m2", "W/m²"},
    {Channel::kTBackC, "t_back_c", "°C"},
    {Channel::kTPvC, "t_pv_c", "°C"},
    {Channel::kPElW, "p_el_w", "W"},
    {Channel::kQThW, "q_th_w", "W"},
    {Channel::kValid, "valid", "0/1"},
}};

constexpr std::string_view ChannelName(Channel c) {
  return kChannels[static_cast<std::size_t>(c)].name;
}

constexpr std::optional<Channel> ChannelFromName(std::string_view name) {
  for (const ChannelInfo& info : kChannels) {
    if (info.name == name) return info.channel;
  }
  return std::nullopt;
}

// Air channels that only the sky estimate reads (SkyTemperaturesC,
// core/model/thermal_model.h): the canonical CSV's optional columns rh_pct
// and p_air_hpa. Series carries them beside the channels above; they are no
// model input of the paper, so the SQLite store, the Modbus register map and
// the physical limits of the CSV reader do not know them (the sky estimate
// skips a value outside 0 < RH ≤ 100 %, 300 ≤ p ≤ 1100 hPa).
enum class AirChannel : std::size_t {
  kRhPct,    // relative humidity of the ambient air, %
  kPAirHpa,  // air pressure, hPa
  kCount
};

inline constexpr std::size_t kNumAirChannels = static_cast<std::size_t>(AirChannel::kCount);

struct AirChannelInfo {
  AirChannel channel;
  std::string_view name;  // canonical CSV column name
  std::string_view unit;
};

inline constexpr std::array<AirChannelInfo, kNumAirChannels> kAirChannels = {{
    {AirChannel::kRhPct, "rh_pct", "%"},
    {AirChannel::kPAirHpa, "p_air_hpa", "hPa"},
}};

constexpr std::optional<AirChannel> AirChannelFromName(std::string_view name) {
  for (const AirChannelInfo& info : kAirChannels) {
    if (info.name == name) return info.channel;
  }
  return std::nullopt;
}

}  // namespace pvtwin
