// Config values: units converted at the edge, defaults as documented, the
// shipped examples and error handling that golden folders cannot express.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "config/plant_config.h"
#include "core/common/units.h"
#include "io/modbus/register_codec.h"

namespace pvtwin {
namespace {

const std::string kConfigGoldenPrefix = std::string(PVTWIN_GOLDEN_DIR) + "/config/";
const std::string kExamplesDir = std::string(PVTWIN_GOLDEN_DIR) + "/../../config/examples/";

constexpr char kMinimalPlant[] =
    "[plant]\nlatitude_deg = 47.358\nlongitude_deg = 16.128\ntilt_deg = 20\n"
    "azimuth_deg = 180\narea_m2 = 1.8\n";

TEST(ConfigLoad, FullConfigValuesAreReadAndAnglesConvertedToRadians) {
  const std::string path = kConfigGoldenPrefix + "ok_full/config.toml";
  Config config;
  Diagnostics errors;
  ASSERT_TRUE(LoadConfig(path, &config, &errors)) << errors.front().ToString();
  const Plant& p = config.plant;
  EXPECT_DOUBLE_EQ(p.latitude_rad, DegToRad(-33.9));
  EXPECT_DOUBLE_EQ(p.longitude_rad, DegToRad(-70.6));
  EXPECT_DOUBLE_EQ(p.elevation_m, 520);
  EXPECT_DOUBLE_EQ(p.tilt_rad, DegToRad(35));
  EXPECT_DOUBLE_EQ(p.azimuth_rad, 0.0);
  EXPECT_DOUBLE_EQ(p.area_m2, 16.2);
  EXPECT_DOUBLE_EQ(p.fluid_cp_j_kgk, 3800);
  EXPECT_DOUBLE_EQ(p.fluid_density_kg_m3, 1030);
  EXPECT_DOUBLE_EQ(p.ground_albedo, 0.25);
  EXPECT_DOUBLE_EQ(p.iam_b0, 0.1);
  EXPECT_DOUBLE_EQ(p.pv_t_ref_c, 25);
  EXPECT_DOUBLE_EQ(p.pv_g_ref_w_m2, 1000);
  EXPECT_DOUBLE_EQ(p.pv_temp_coeff_per_k, -0.0041);
  EXPECT_DOUBLE_EQ(p.pv_irr_coeff_m2_w, 3.6e-5);
  EXPECT_EQ(config.storage.path, "/srv/pvtwin/field.db");
  EXPECT_EQ(config.storage.raw_retention_days, 7);
  EXPECT_DOUBLE_EQ(config.poll.period_s, 2);
  EXPECT_EQ(config.calibration.variant, "1N1Cwr+transport_delay");
  EXPECT_EQ(config.calibration.window_days, 21);
  EXPECT_DOUBLE_EQ(config.calibration.step_s, 120);
  EXPECT_EQ(config.calibration.at, "03:30");
  EXPECT_EQ(config.calibration.timezone, "America/Santiago");
  EXPECT_DOUBLE_EQ(config.forecast.horizon_h, 48);
  EXPECT_DOUBLE_EQ(config.forecast.refresh_min, 15);
  EXPECT_DOUBLE_EQ(config.forecast.weather_refresh_min, 30);
  EXPECT_DOUBLE_EQ(config.forecast.weather_timeout_s, 20);
  EXPECT_DOUBLE_EQ(p.collector_height_m, 4);
  // The template's placeholders take the plant's values; Open-Meteo's azimuth
  // counts from south (a north-facing plane in the southern hemisphere: -180).
  EXPECT_EQ(ExpandWeatherUrl(config.forecast.weather_url, p),
            "https://api.open-meteo.com/v1/forecast?latitude=-33.9&longitude=-70.6&tilt=35&"
            "azimuth=-180&minutely_15=global_tilted_irradiance");
  EXPECT_EQ(config.source_path, path);
}

TEST(ConfigLoad, PlantKeyValuesRoundTrip) {
  Config config;
  Diagnostics errors;
  ASSERT_TRUE(LoadConfig(kConfigGoldenPrefix + "ok_full/config.toml", &config, &errors));
  const std::vector<std::pair<std::string, double>> values = PlantKeyValues(config.plant);
  EXPECT_EQ(values[0].first, "latitude_deg");
  EXPECT_NEAR(values[0].second, -33.9, 1e-12);
  Plant back;
  std::string error;
  ASSERT_TRUE(PlantFromKeyValues(values, &back, &error)) << error;
  const std::vector<std::pair<std::string, double>> again = PlantKeyValues(back);
  ASSERT_EQ(again.size(), values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    EXPECT_EQ(again[i].first, values[i].first);
    EXPECT_NEAR(again[i].second, values[i].second, 1e-9) << values[i].first;
  }
  EXPECT_FALSE(PlantFromKeyValues({{"latitude_deg", 47.0}}, &back, &error));
  EXPECT_EQ(error, "longitude_deg: missing");
}

TEST(ConfigLoad, OmittedKeysTakeTheDocumentedDefaults) {
  Config config;
  Diagnostics errors;
  ASSERT_TRUE(ParseConfig(kMinimalPlant, "config.toml", &config, &errors));
  const Plant defaults;
  const Plant& p = config.plant;
  EXPECT_DOUBLE_EQ(p.latitude_rad, 47.358 * kPi / 180);
  EXPECT_DOUBLE_EQ(p.azimuth_rad, kPi);
  EXPECT_EQ(p.elevation_m, 0.0);
  // doc/contracts.md's [plant] example values, which core/common/plant.h also uses.
  EXPECT_EQ(p.fluid_cp_j_kgk, 3650);
  EXPECT_EQ(p.fluid_density_kg_m3, 1040);
  EXPECT_EQ(p.ground_albedo, 0.2);
  EXPECT_EQ(p.iam_b0, 0.05);
  EXPECT_EQ(p.pv_t_ref_c, 25);
  EXPECT_EQ(p.pv_g_ref_w_m2, 1000);
  EXPECT_EQ(p.pv_temp_coeff_per_k, -0.004);
  EXPECT_EQ(p.pv_irr_coeff_m2_w, 3.6e-5);
  EXPECT_EQ(p.fluid_cp_j_kgk, defaults.fluid_cp_j_kgk);
  EXPECT_EQ(p.pv_irr_coeff_m2_w, defaults.pv_irr_coeff_m2_w);
  // doc/contracts.md's daemon section defaults.
  EXPECT_EQ(config.storage.path, "/var/lib/pvtwin/pvtwin.db");
  EXPECT_EQ(config.storage.raw_retention_days, 30);
  EXPECT_EQ(config.poll.period_s, 5);
  EXPECT_EQ(config.calibration.variant, "2N1Ccolwr");
  EXPECT_EQ(config.calibration.window_days, 14);
  EXPECT_EQ(config.calibration.step_s, 60);
  EXPECT_EQ(config.calibration.at, "02:00");
  EXPECT_EQ(config.calibration.timezone, "Europe/Vienna");
  EXPECT_EQ(config.forecast.horizon_h, 24);
  EXPECT_EQ(config.forecast.refresh_min, 60);
}

TEST(ConfigLoad, ShippedExamplesAreValid) {
  for (const char* name : {"plant.toml", "pvtwin.toml"}) {
    Config config;
    Diagnostics errors;
    EXPECT_TRUE(LoadConfig(kExamplesDir + name, &config, &errors))
        << name << ": " << (errors.empty() ? "" : errors.front().ToString());
    EXPECT_DOUBLE_EQ(config.plant.area_m2, 1.8);
  }
}

// The register-map examples for TCP and RTU check, volume flows included.
TEST(ConfigLoad, ShippedRegisterMapExamplesAreValid) {
  for (const char* name : {"modbus-tcp.toml", "modbus-rtu.toml"}) {
    Config config;
    Diagnostics errors;
    EXPECT_TRUE(LoadConfig(kExamplesDir + name, &config, &errors))
        << name << ": " << (errors.empty() ? "" : errors.front().ToString());
    EXPECT_GE(config.modbus.devices.size(), 2u) << name;
    const bool volume_flow =
        std::any_of(config.modbus.points.begin(), config.modbus.points.end(),
                    [](const ModbusPoint& p) { return p.wire_unit != WireUnit::kChannel; });
    EXPECT_TRUE(volume_flow) << name;
  }
  Config rtu;
  Diagnostics errors;
  ASSERT_TRUE(LoadConfig(kExamplesDir + "modbus-rtu.toml", &rtu, &errors));
  EXPECT_EQ(rtu.modbus.devices[0].Endpoint(), "/dev/ttyUSB0@19200,8E1");
}

TEST(ConfigLoad, MissingFileIsOneErrorNamingThePath) {
  Config config;
  Diagnostics errors;
  EXPECT_FALSE(LoadConfig("/nonexistent/pvtwin.toml", &config, &errors));
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].ToString(),
            "/nonexistent/pvtwin.toml: cannot open: No such file or directory");
}

TEST(ConfigLoad, FailedParseLeavesOutputAndEarlierErrorsAlone) {
  Config config;
  config.calibration.variant = "kept";
  Diagnostics errors = {Diagnostic{"earlier.toml", 1, "", "", "earlier problem"}};
  EXPECT_FALSE(ParseConfig(std::string(kMinimalPlant) + "[poll]\nperiod_s = -1\n", "config.toml",
                           &config, &errors));
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0].rule, "earlier problem");
  EXPECT_EQ(errors[1].ToString(), "config.toml:8: period_s = -1: must be within [1, 60]");
  EXPECT_EQ(config.calibration.variant, "kept");
}

TEST(ConfigLoad, NonFiniteNumbersAreRejected) {
  Config config;
  Diagnostics errors;
  EXPECT_FALSE(ParseConfig(
      "[plant]\nlatitude_deg = nan\nlongitude_deg = 16\ntilt_deg = 20\nazimuth_deg = 180\n"
      "area_m2 = inf\n",
      "config.toml", &config, &errors));
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0].ToString(), "config.toml:2: latitude_deg = nan: must be a finite number");
  EXPECT_EQ(errors[1].ToString(), "config.toml:6: area_m2 = inf: must be a finite number");
}

TEST(ConfigLoad, BoundariesOfTheRanges) {
  const auto errors_for = [](const std::string& extra) {
    Config config;
    Diagnostics errors;
    ParseConfig(std::string(kMinimalPlant) + extra, "config.toml", &config, &errors);
    return errors.size();
  };
  EXPECT_EQ(errors_for("iam_b0 = 0\nground_albedo = 1\n"), 0u);
  EXPECT_EQ(errors_for("pv_temp_coeff_per_k = -0.02\npv_irr_coeff_m2_w = -1e-3\n"), 0u);
  EXPECT_EQ(errors_for("[calibration]\nstep_s = 5\nat = \"23:59\"\nwindow_days = 60\n"), 0u);
  EXPECT_EQ(errors_for("[calibration]\nstep_s = 900\n[forecast]\nhorizon_h = 168\n"), 0u);
  EXPECT_EQ(errors_for("[calibration]\nstep_s = 60.5\n"), 1u);
  EXPECT_EQ(errors_for("[calibration]\nstep_s = 4\n"), 1u);
  EXPECT_EQ(errors_for("[calibration]\nat = \"02:00 \"\n"), 1u);
  EXPECT_EQ(errors_for("[forecast]\nhorizon_h = 0\n"), 1u);
  // A value out of the int range must not wrap around.
  EXPECT_EQ(errors_for("[storage]\nraw_retention_days = 9999999999\n"), 1u);
  EXPECT_EQ(errors_for("[diagnosis]\nenabled = false\nevery_days = 1\ntimeout_s = 1\nkeep = 1\n"
                       "[monitor]\ndrift_days = 2\nalarm_days = 60\n"),
            0u);
}

// A Modbus sentinel must be a raw value the register can hold. An f32
// sentinel is kept as the float it names: 0.1 in the config is the register
// 0x3DCCCCCD (0.1f, IEEE 754 single), which widened is 0.100000001490116…,
// not the double 0.1, so the reading it marks is rejected only if the config
// keeps the float. The golden folder modbus_nan_value_outside_type has the
// messages for values no register of the type holds.
TEST(ConfigLoad, ModbusSentinelIsTheRegisterTypesValue) {
  const std::string map =
      "[[modbus.device]]\nname = \"d\"\nhost = \"127.0.0.1\"\n"
      "[[modbus.point]]\ndevice = \"d\"\nchannel = \"t_in_c\"\ntable = \"input\"\n"
      "address = 0\ntype = \"f32\"\nnan_value = 0.1\n"
      "[[modbus.point]]\ndevice = \"d\"\nchannel = \"t_out_c\"\ntable = \"input\"\n"
      "address = 2\ntype = \"i16\"\nnan_value = ";
  Config config;
  Diagnostics errors;
  ASSERT_TRUE(
      ParseConfig(std::string(kMinimalPlant) + map + "-32768\n", "config.toml", &config, &errors))
      << errors.front().ToString();
  ASSERT_EQ(config.modbus.points.size(), 2u);
  const ModbusPoint& f32 = config.modbus.points[0];
  EXPECT_EQ(*f32.nan_value, static_cast<double>(0.1f));
  const std::uint16_t sentinel[] = {0x3DCC, 0xCCCD};
  EXPECT_TRUE(DecodePoint(f32, sentinel).rejected);
  const std::uint16_t one[] = {0x3F80, 0x0000};  // 1.0f
  EXPECT_FALSE(DecodePoint(f32, one).rejected);
  EXPECT_EQ(*config.modbus.points[1].nan_value, -32768.0);

  errors.clear();
  EXPECT_FALSE(
      ParseConfig(std::string(kMinimalPlant) + map + "1e9\n", "config.toml", &config, &errors));
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].ToString(),
            "config.toml:23: nan_value = 1e9: must be an integer within [-32768, 32767], the "
            "range of i16");
}

// The [diagnosis] and [monitor] sections: defaults, values, and each bad
// value named with file, line, key and rule.
TEST(ConfigLoad, DiagnosisAndMonitorSections) {
  Config config;
  Diagnostics errors;
  ASSERT_TRUE(ParseConfig(kMinimalPlant, "config.toml", &config, &errors));
  EXPECT_TRUE(config.diagnosis.enabled);
  EXPECT_EQ(config.diagnosis.every_days, 7);
  EXPECT_EQ(config.diagnosis.timeout_s, 1800);
  EXPECT_EQ(config.diagnosis.keep, 10);
  EXPECT_EQ(config.monitor.drift_days, 28);
  EXPECT_EQ(config.monitor.alarm_days, 3);
  EXPECT_TRUE(config.calibration.refit_full_window);
  ASSERT_TRUE(ParseConfig(std::string(kMinimalPlant) + "[calibration]\nrefit_full_window = false\n",
                          "config.toml", &config, &errors));
  EXPECT_FALSE(config.calibration.refit_full_window);
  ASSERT_TRUE(ParseConfig(std::string(kMinimalPlant) +
                              "[diagnosis]\nenabled = false\nevery_days = 14\n[monitor]\n"
                              "alarm_days = 5\n",
                          "config.toml", &config, &errors));
  EXPECT_FALSE(config.diagnosis.enabled);
  EXPECT_EQ(config.diagnosis.every_days, 14);
  EXPECT_EQ(config.monitor.alarm_days, 5);
  errors.clear();
  EXPECT_FALSE(ParseConfig(std::string(kMinimalPlant) +
                               "[diagnosis]\nenabled = \"yes\"\nevery_days = 0\ntimeout_s = 0.5\n"
                               "[monitor]\ndrift_days = 1\nalarm_days = 2.5\n",
                           "config.toml", &config, &errors));
  ASSERT_EQ(errors.size(), 5u);
  EXPECT_EQ(errors[0].ToString(), "config.toml:8: enabled = \"yes\": expected true or false");
  EXPECT_NE(errors[1].ToString().find("config.toml:9: every_days = 0: "), std::string::npos)
      << errors[1].ToString();
  EXPECT_NE(errors[2].ToString().find("config.toml:10: timeout_s = 0.5: "), std::string::npos)
      << errors[2].ToString();
  EXPECT_NE(errors[3].ToString().find("config.toml:12: drift_days = 1: "), std::string::npos)
      << errors[3].ToString();
  EXPECT_EQ(errors[4].ToString(), "config.toml:13: alarm_days = 2.5: expected an integer");
}

// [log] status_min: the health line's period, 0 turning it off.
TEST(ConfigLoad, LogSectionStatusMin) {
  Config config;
  Diagnostics errors;
  ASSERT_TRUE(ParseConfig(kMinimalPlant, "config.toml", &config, &errors));
  EXPECT_EQ(config.log.status_min, 15);
  for (const int minutes : {0, 1, 1440}) {
    ASSERT_TRUE(ParseConfig(std::string(kMinimalPlant) + "[log]\nstatus_min = " +
                                std::to_string(minutes) + "\n",
                            "config.toml", &config, &errors));
    EXPECT_EQ(config.log.status_min, minutes);
  }
  EXPECT_FALSE(ParseConfig(std::string(kMinimalPlant) + "[log]\nstatus_min = 2.5\nlevel = 3\n",
                           "config.toml", &config, &errors));
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0].ToString(), "config.toml:8: status_min = 2.5: expected an integer");
  EXPECT_EQ(errors[1].ToString(), "config.toml:9: level = 3: unknown key");
}

TEST(ConfigLoad, UploadSectionIsOptionalWithDocumentedDefaults) {
  Config config;
  Diagnostics errors;
  ASSERT_TRUE(ParseConfig(kMinimalPlant, "config.toml", &config, &errors));
  EXPECT_FALSE(config.upload.enabled);
  const std::string text = std::string(kMinimalPlant) +
                           "[upload]\nurl = \"postgresql://pvtwin@fleet.example.org/fleet\"\n"
                           "plant_id = \"north-1\"\n";
  ASSERT_TRUE(ParseConfig(text, "config.toml", &config, &errors)) << errors.front().ToString();
  EXPECT_TRUE(config.upload.enabled);
  EXPECT_EQ(config.upload.url, "postgresql://pvtwin@fleet.example.org/fleet");
  EXPECT_EQ(config.upload.plant_id, "north-1");
  EXPECT_EQ(config.upload.password_file, "");
  EXPECT_DOUBLE_EQ(config.upload.interval_s, 60);
  EXPECT_EQ(config.upload.batch_rows, 5000);
  EXPECT_EQ(config.upload.forecast_days, 7);
}

TEST(ConfigLoad, UploadUrlWithAPasswordIsRejectedInEveryFormWithoutShowingIt) {
  for (const std::string url : {"postgresql://u:pw1234@h/db", "postgresql://u@h/db?password=pw1234",
                                "host=h dbname=db password=pw1234", "host=h password='pw1234'"}) {
    Config config;
    Diagnostics errors;
    const std::string text =
        std::string(kMinimalPlant) + "[upload]\nurl = \"" + url + "\"\nplant_id = \"p\"\n";
    ASSERT_FALSE(ParseConfig(text, "config.toml", &config, &errors)) << url;
    ASSERT_EQ(errors.size(), 1u) << url;
    EXPECT_EQ(errors[0].line, 8) << url;
    EXPECT_EQ(errors[0].field, "url");
    EXPECT_NE(errors[0].rule.find("holds a password"), std::string::npos);
    EXPECT_EQ(errors[0].ToString().find("pw1234"), std::string::npos) << errors[0].ToString();
  }
}

}  // namespace
}  // namespace pvtwin

namespace pvtwin {
namespace {

// A volume-flow meter maps as flow_l_h or flow_m3_h: it feeds flow_kg_s
// through [plant] fluid_density_kg_m3, in the poller as in the simulator.
TEST(ConfigModbus, VolumeFlowChannelsFeedTheMassFlowThroughTheDensity) {
  const auto point = [](const std::string& channel, const std::string& type) {
    const std::string map =
        "fluid_density_kg_m3 = 1000\n"
        "[[modbus.device]]\nname = \"meter\"\nhost = \"127.0.0.1\"\n"
        "[[modbus.point]]\ndevice = \"meter\"\nchannel = \"" +
        channel + "\"\ntable = \"input\"\naddress = 0\ntype = \"" + type + "\"\n";
    Config config;
    Diagnostics errors;
    EXPECT_TRUE(ParseConfig(std::string(kMinimalPlant) + map, "config.toml", &config, &errors))
        << errors.front().ToString();
    return config.modbus.points.empty() ? ModbusPoint{} : config.modbus.points.front();
  };
  const ModbusPoint l_h = point("flow_l_h", "u16");
  const ModbusPoint m3_h = point("flow_m3_h", "f32");
  EXPECT_EQ(l_h.channel, Channel::kMdotKgS);
  EXPECT_EQ(m3_h.channel, Channel::kMdotKgS);
  EXPECT_EQ(l_h.ChannelNameInMap(), "flow_l_h");
  EXPECT_EQ(m3_h.ChannelNameInMap(), "flow_m3_h");
  EXPECT_NEAR(PointToChannelUnit(l_h, 360.0), 0.1, 1e-12);  // 360 L/h of 1000 kg/m³
  EXPECT_NEAR(PointToChannelUnit(m3_h, 0.36), 0.1, 1e-12);
  EXPECT_NEAR(ChannelToPointUnit(l_h, 0.1), 360.0, 1e-9);
  Config config;
  Diagnostics errors;
  // Both feed one channel: a second point for it is refused.
  const std::string twice =
      "[[modbus.device]]\nname = \"meter\"\nhost = \"127.0.0.1\"\n"
      "[[modbus.point]]\ndevice = \"meter\"\nchannel = \"flow_l_h\"\ntable = \"input\"\n"
      "address = 0\ntype = \"u16\"\n"
      "[[modbus.point]]\ndevice = \"meter\"\nchannel = \"flow_kg_s\"\ntable = \"input\"\n"
      "address = 1\ntype = \"u16\"\n";
  errors.clear();
  EXPECT_FALSE(ParseConfig(std::string(kMinimalPlant) + twice, "config.toml", &config, &errors));
}

}  // namespace
}  // namespace pvtwin
