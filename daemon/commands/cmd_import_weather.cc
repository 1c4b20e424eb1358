// pvtwin import-weather: a weather forecast (Open-Meteo JSON, hourly or
// 15-min, or a canonical CSV) into table weather_forecast at 1 min, for the
// daemon's next forecast (daemon/service/weather_import.h says how). The plant comes
// from --config, else from the store's plant_config (written by `pvtwin run`).
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "config/plant_config.h"
#include "daemon/commands/commands.h"
#include "daemon/commands/inputs.h"
#include "daemon/service/store_cli.h"
#include "daemon/service/weather_import.h"

namespace pvtwin::cli {

namespace {

struct ImportWeatherArgs {
  std::string config;
  std::string db;
  std::string file;
};

bool PlantFromStore(Store& store, Plant* plant) {
  std::vector<std::pair<std::string, double>> values;
  std::string error;
  if (!store.ReadPlantConfig(&values, &error)) {
    std::cerr << store.path() << ": " << error << "\n";
    return false;
  }
  if (values.empty()) {
    std::cerr << store.path()
              << ": the store holds no plant yet (pvtwin run records it); give --config with "
                 "the [plant] section\n";
    return false;
  }
  if (!PlantFromKeyValues(values, plant, &error)) {
    std::cerr << store.path() << ": plant_config: " << error << "; give --config\n";
    return false;
  }
  return true;
}

int RunImportWeather(const ImportWeatherArgs& a) {
  Config config;
  if (!a.config.empty() && !LoadConfigOrReport(a.config, &config)) return kExitBadInput;
  if (a.config.empty() && a.db.empty()) {
    std::cerr << "import-weather: give --db (the SQLite file) or --config (its [storage] path)\n";
    return kExitBadInput;
  }
  const std::string path = a.db.empty() ? config.storage.path : a.db;
  if (a.config.empty() && !std::filesystem::exists(path)) {
    std::cerr << "--db = " << path << ": no such database (without --config the plant comes "
              << "from the store)\n";
    return kExitBadInput;
  }
  std::unique_ptr<Store> store;
  if (!OpenStoreOrReport(path, StoreOptionsFor(config), &store)) return kExitRuntime;
  Plant plant = config.plant;
  if (a.config.empty() && !PlantFromStore(*store, &plant)) return kExitBadInput;
  std::string text;
  {
    std::ifstream in(a.file, std::ios::binary);
    if (!in) {
      std::cerr << a.file << ": cannot open the file\n";
      return kExitBadInput;
    }
    std::ostringstream buffer;
    buffer << in.rdbuf();
    text = buffer.str();
  }
  const std::string source = "import-weather " + a.file;
  const WeatherImportResult r = ImportWeatherText(*store, plant, text, a.file, source);
  for (const std::string& note : r.file.notes) std::cerr << "warning: " << note << "\n";
  switch (r.status) {
    case WeatherImportResult::Status::kBadInput:
      for (const Diagnostic& d : r.errors) std::cerr << d.ToString() << "\n";
      return kExitBadInput;
    case WeatherImportResult::Status::kStoreFailed:
      std::cerr << path << ": " << r.store_error << "\n";
      return kExitRuntime;
    case WeatherImportResult::Status::kOk:
      break;
  }
  for (const std::string& origin : r.summary.origins) std::cerr << "  " << origin << "\n";
  // Physically impossible irradiance is a warning, not an error: the rows
  // are stored clipped and marked (weather_import.h), the exit code stays 0.
  for (const std::string& warning : r.Warnings()) std::cerr << "warning: " << warning << "\n";
  std::cerr << r.SummaryLine(source) << " into " << store->path() << "\n";
  return kExitOk;
}

}  // namespace

void RegisterImportWeather(CLI::App& app) {
  auto args = std::make_shared<ImportWeatherArgs>();
  CLI::App* cmd = app.add_subcommand(
      "import-weather",
      "Load a weather forecast into the store's weather_forecast table at 1 min, for the\n"
      "daemon's forecasts: Open-Meteo JSON (hourly or minutely_15; global_tilted_irradiance\n"
      "or shortwave/diffuse/direct radiation, temperature_2m, wind_speed_10m in m/s or km/h,\n"
      "dew_point_2m or relative_humidity_2m, cloud_cover) or a canonical CSV (time and\n"
      "weather_forecast's columns). Irradiance keeps each interval's energy (clear-sky index),\n"
      "no minute above 2x its clear sky + 50 W/m²: an interval carrying more (a time-zone\n"
      "error) is stored clipped, marked in `source` and named in a warning (exit code 0);\n"
      "temperatures and wind are interpolated, wind is brought from 10 m to [plant]\n"
      "collector_height_m (power law, 1/7), the sky temperature comes from Brunt's sky model\n"
      "with cloud cover when the file has no long-wave. Rows of the same minutes are replaced.\n"
      "The plant comes from --config or, without it, from the store (recorded by pvtwin run).");
  cmd->add_option("--config", args->config, "TOML config ([plant], [storage] path)");
  cmd->add_option("--db", args->db, "SQLite file to use instead of [storage] path");
  cmd->add_option("file", args->file, "Open-Meteo JSON or canonical CSV")->required();
  cmd->callback([args] { SetExitCode(RunImportWeather(*args)); });
}

}  // namespace pvtwin::cli
