// The "fit" object of params.json has one type on both sides (issue 51):
// `pvtwin calibrate` writes CalibrationFit::ToJson and the daemon reads it
// back with CalibrationFit::FromParamsJson into its calibration and
// calibration_param rows. Checked on a real calibrate run on the htw saar
// days (tests/data/htwsaar-pvt/PROVENANCE.md).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "daemon/service/calibration_fit.h"
#include "tests/support/files.h"
#include "tests/support/fixtures.h"
#include "tests/support/run_pvtwin.h"

namespace pvtwin {
namespace {

namespace fs = std::filesystem;

using testing::HtwSaarArg;

// Read back and written again, the fit calibrate wrote is the same text,
// byte for byte: every member is read, with its type (an integer stays an
// integer, a null standard error stays null), in the writer's key order.
TEST(CalibrationFit, WhatCalibrateWritesReadsBackToTheSameText) {
  testing::ScratchDir dir("calibration_fit");
  const testing::ProcessResult run = testing::RunPvtwin(
      dir.path(), "calibrate --config " + HtwSaarArg("plant.toml") + " --csv " +
                      HtwSaarArg("day3_clear_medium_dT.csv") + " --test-csv " +
                      HtwSaarArg("day1_clear_low_dT.csv") + " --variant 1N1Cwr --out params.json");
  ASSERT_EQ(run.exit_code, 0) << run.err << run.out;
  const std::string text = testing::ReadFile(dir.path() / "params.json");
  const nlohmann::ordered_json written = nlohmann::ordered_json::parse(text)["fit"];
  ASSERT_TRUE(written.is_object()) << text;

  CalibrationFit fit;
  ASSERT_TRUE(CalibrationFit::FromParamsJson(text, &fit));
  EXPECT_EQ(fit.ToJson(), written.dump());
  CalibrationFit again;
  ASSERT_TRUE(CalibrationFit::FromJson(written.dump(), &again));
  EXPECT_EQ(again.ToJson(), written.dump());

  // What the daemon takes from it.
  EXPECT_EQ(fit.algorithm, "lad_lm");
  EXPECT_EQ(fit.simulations, written["simulations"].get<int>());
  EXPECT_GT(fit.simulations, 0);
  ASSERT_TRUE(fit.held_out.has_value());
  EXPECT_EQ(fit.held_out->rows, written["held_out"]["rows"].get<std::size_t>());
  ASSERT_EQ(fit.parameters.size(), written["parameters"].size());
  ASSERT_FALSE(fit.parameters.empty());
  for (std::size_t i = 0; i < fit.parameters.size(); ++i) {
    const nlohmann::ordered_json& p = written["parameters"][i];
    EXPECT_EQ(fit.parameters[i].name, p["name"].get<std::string>());
    EXPECT_EQ(fit.parameters[i].value, p["value"].get<double>());
    EXPECT_EQ(std::isnan(fit.parameters[i].std_error), p["std_error"].is_null());
    EXPECT_EQ(fit.parameters[i].status, p["status"].get<std::string>());
  }
  // The parameter values are those of the file's "params".
  const nlohmann::ordered_json params = nlohmann::ordered_json::parse(text)["params"];
  for (const FitParameter& p : fit.parameters) {
    if (params.contains(p.name)) {
      EXPECT_EQ(p.value, params[p.name].get<double>()) << p.name;
    }
  }
}

// A fit written by another (older, hand-edited) tool: entries that cannot
// be parameter rows are left out, members of another type keep their
// defaults instead of stopping the reader.
TEST(CalibrationFit, EntriesOfTheWrongShapeAreLeftOut) {
  CalibrationFit fit;
  ASSERT_TRUE(CalibrationFit::FromJson(
      R"({"simulations": "many", "at_bounds": ["a_pv", 3],
          "parameters": [{"name": "u_front_w_m2k", "value": 12.5, "std_error": null, "unit": 1},
                         {"name": "eta_ref"}, {"value": 1}, 7]})",
      &fit));
  EXPECT_EQ(fit.simulations, 0);
  EXPECT_EQ(fit.at_bounds, std::vector<std::string>{"a_pv"});
  ASSERT_EQ(fit.parameters.size(), 1u);
  EXPECT_EQ(fit.parameters[0].name, "u_front_w_m2k");
  EXPECT_EQ(fit.parameters[0].value, 12.5);
  EXPECT_TRUE(std::isnan(fit.parameters[0].std_error));
  EXPECT_EQ(fit.parameters[0].unit, "");
  EXPECT_FALSE(fit.held_out.has_value());
  EXPECT_FALSE(CalibrationFit::FromJson("[1, 2]", &fit));
  EXPECT_FALSE(CalibrationFit::FromParamsJson("not json", &fit));
  // A params.json without a fit (written by hand): an empty fit.
  ASSERT_TRUE(CalibrationFit::FromParamsJson(R"({"variant": "1N", "params": {}})", &fit));
  EXPECT_TRUE(fit.parameters.empty());
}

}  // namespace
}  // namespace pvtwin
