// The fixed description of one PVT collector field: site, orientation, fluid
// and PV reference data. Parsed and validated from the [plant] section of the
// TOML config (config/plant_config.h); angles are radians here.
#pragma once

namespace pvtwin {

// Where the model's sky temperature comes from ([plant] sky).
enum class SkySource {
  kAuto,       // the long-wave channel, unless it is implausible (then kEstimated)
  kMeasured,   // t_sky_c, else lw_down_w_m2, always
  kEstimated,  // from the air temperature and dew point (Berdahl & Martin 1984) where the
               // data have rh_pct, else from the air temperature (Swinbank 1963)
};

// Which sky the model's sky temperature is, as SkySource chose it
// (SkyTemperaturesC, core/model/thermal_model.h).
enum class SkyUsed {
  kMeasured,        // t_sky_c, else lw_down_w_m2
  kAirTemperature,  // estimated from t_amb_c (Swinbank 1963)
  kDewPoint,        // estimated from t_amb_c and rh_pct (Berdahl & Martin 1984)
};

struct Plant {
  double latitude_rad = 0.0;   // north positive
  double longitude_rad = 0.0;  // east positive
  double elevation_m = 0.0;    // above sea level (solar position refraction only)
  double tilt_rad = 0.0;       // collector slope from horizontal, paper β
  double azimuth_rad = 0.0;    // from north, clockwise (π = south), paper γ
  double area_m2 = 1.8;        // nameplate gross area A_PVT
  double fluid_cp_j_kgk = 3650.0;
  double fluid_density_kg_m3 = 1040.0;
  double ground_albedo = 0.2;           // paper ρ_gnd
  double iam_b0 = 0.05;                 // Souka & Safwat first-order IAM coefficient b0
  double pv_t_ref_c = 25.0;             // paper T_PVref
  double pv_g_ref_w_m2 = 1000.0;        // paper I_gtref
  double pv_temp_coeff_per_k = -0.004;  // paper f_corr_T
  double pv_irr_coeff_m2_w = 3.6e-5;    // paper f_corr_I
  // Height of the collector (and of the wind the model was calibrated on)
  // above ground, m: a weather forecast's 10 m wind is brought to it
  // (core/forecast/weather_resample.h). 10 = the forecast's wind as it is.
  double collector_height_m = 10.0;
  SkySource sky = SkySource::kAuto;

  bool operator==(const Plant&) const = default;
};

}  // namespace pvtwin
