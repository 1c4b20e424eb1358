// Weather forecasts fetched over HTTP (issue 15), with real parts: a real
// HTTP/1.1 server on loopback (tests/support/http_server.h) serving the
// recorded Open-Meteo answers of tests/weather/data, HTTP errors, a slow
// answer and a cut-off body; libcurl as the daemon uses it; the daemon's
// fetch thread; and the real `pvtwin import-weather` and `pvtwin run`
// processes.
#include <gtest/gtest.h>
#include <signal.h>
#include <sqlite3.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "config/config_edit.h"
#include "config/plant_config.h"
#include "core/common/clock.h"
#include "core/forecast/weather_resample.h"
#include "daemon/service/weather_worker.h"
#include "io/platform/child_process.h"
#include "io/store/store.h"
#include "io/weather/http_client.h"
#include "tests/support/files.h"
#include "tests/support/fixtures.h"
#include "tests/support/http_server.h"
#include "tests/support/run_pvtwin.h"
#include "tests/support/stop_timeout.h"

namespace pvtwin {
namespace {

namespace fs = std::filesystem;
using testing::LoopbackHttpServer;
using testing::ReadFile;
using testing::RunPvtwin;
using testing::ScratchDir;
using testing::UnitStopTimeoutS;

const fs::path kData = fs::path(PVTWIN_SOURCE_DIR) / "tests" / "weather" / "data";
using testing::kExamplePlantConfig;

LoopbackHttpServer::Answer Recorded(const std::string& file) {
  LoopbackHttpServer::Answer a;
  a.body = ReadFile(kData / file);
  return a;
}

// The recorded hourly answer (2024-06-01/02, GMT) with its time stamps
// rewritten: `first` is the first stamp "YYYY-MM-DDTHH:00" of 48 hourly ones,
// the values unchanged. 2025-12-20T00:00 puts June's light into December's
// short days; 2024-06-01T03:00 is the answer 3 h late, as a provider in UTC+3
// local time would send it labelled GMT.
std::string Restamped(int year, int month, int day, int hour) {
  nlohmann::json j = nlohmann::json::parse(ReadFile(kData / "open-meteo-hourly.json"));
  nlohmann::json& times = j["hourly"]["time"];
  for (std::size_t i = 0; i < times.size(); ++i) {
    const int h = hour + static_cast<int>(i);
    char buf[32];
    std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:00", year, month, day + h / 24, h % 24);
    times[i] = buf;
  }
  return j.dump();
}

bool WaitFor(double timeout_s, const std::function<bool()>& done) {
  const double deadline = WallNowS() + timeout_s;
  while (WallNowS() < deadline) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return done();
}

// --- libcurl against the loopback server ---------------------------------

class HttpClientTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string error;
    ASSERT_TRUE(server_.Start(0, &error)) << error;
  }
  HttpResponse Get(const std::string& path, double timeout_s = 5.0) {
    HttpOptions options;
    options.total_timeout_s = timeout_s;
    options.connect_timeout_s = timeout_s;
    return HttpGet(server_.Url(path), options, nullptr);
  }
  LoopbackHttpServer server_;
};

TEST_F(HttpClientTest, ServesTheRecordedAnswer) {
  server_.SetAnswer("/v1/forecast", Recorded("open-meteo-hourly.json"));
  const HttpResponse r = Get("/v1/forecast?latitude=47.358&longitude=16.128");
  EXPECT_EQ(r.outcome, HttpResponse::Outcome::kOk) << r.error;
  EXPECT_EQ(r.status, 200);
  EXPECT_EQ(r.body, ReadFile(kData / "open-meteo-hourly.json"));
  EXPECT_EQ(server_.last_target(), "/v1/forecast?latitude=47.358&longitude=16.128");
}

TEST_F(HttpClientTest, HttpErrorsComeWithTheirStatus) {
  for (int status : {500, 503}) {
    LoopbackHttpServer::Answer a;
    a.status = status;
    a.body = "{\"error\":true,\"reason\":\"overloaded\"}";
    server_.SetAnswer("/e" + std::to_string(status), a);
    const HttpResponse r = Get("/e" + std::to_string(status));
    EXPECT_EQ(r.outcome, HttpResponse::Outcome::kHttpError);
    EXPECT_EQ(r.status, status);
    EXPECT_EQ(r.error, "HTTP " + std::to_string(status));
  }
  const HttpResponse missing = Get("/nowhere");
  EXPECT_EQ(missing.outcome, HttpResponse::Outcome::kHttpError);
  EXPECT_EQ(missing.status, 404);
}

TEST_F(HttpClientTest, ASlowAnswerRunsIntoTheTimeout) {
  LoopbackHttpServer::Answer slow = Recorded("open-meteo-hourly.json");
  slow.delay_s = 5.0;
  server_.SetAnswer("/slow", slow);
  const double start = WallNowS();
  const HttpResponse r = Get("/slow", 1.0);
  EXPECT_EQ(r.outcome, HttpResponse::Outcome::kTimeout) << r.error;
  EXPECT_LT(WallNowS() - start, 3.0);
}

TEST_F(HttpClientTest, ABodyCutShortIsABrokenTransfer) {
  LoopbackHttpServer::Answer cut = Recorded("open-meteo-hourly.json");
  cut.truncate = true;
  server_.SetAnswer("/cut", cut);
  const HttpResponse r = Get("/cut");
  EXPECT_EQ(r.outcome, HttpResponse::Outcome::kBroken) << r.error;
}

TEST_F(HttpClientTest, NoServerIsUnreachable) {
  const int port = server_.port();
  server_.Stop();
  HttpOptions options;
  const HttpResponse r =
      HttpGet("http://127.0.0.1:" + std::to_string(port) + "/v1/forecast", options, nullptr);
  EXPECT_EQ(r.outcome, HttpResponse::Outcome::kUnreachable) << r.error;
}

TEST_F(HttpClientTest, TheAbortFlagEndsATransferInProgress) {
  LoopbackHttpServer::Answer slow = Recorded("open-meteo-hourly.json");
  slow.delay_s = 20.0;
  server_.SetAnswer("/slow", slow);
  std::atomic<bool> abort{false};
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    abort = true;
  });
  const double start = WallNowS();
  HttpOptions options;
  const HttpResponse r = HttpGet(server_.Url("/slow"), options, &abort);
  stopper.join();
  EXPECT_EQ(r.outcome, HttpResponse::Outcome::kAborted) << r.error;
  EXPECT_LT(WallNowS() - start, 2.0);
}

// A commercial weather API's key stays out of log lines and the store.
TEST(UrlForLogs, HidesCredentialLikeQueryParameters) {
  EXPECT_EQ(UrlForLogs("https://customer-api.open-meteo.com/v1/forecast?latitude=47.4&apikey="
                       "s3cr3t&hourly=temperature_2m&Token=abc"),
            "https://customer-api.open-meteo.com/v1/forecast?latitude=47.4&apikey=***&hourly="
            "temperature_2m&Token=***");
  EXPECT_EQ(UrlForLogs("http://127.0.0.1:8080/v1/forecast"), "http://127.0.0.1:8080/v1/forecast");
  EXPECT_EQ(UrlForLogs("http://h/f?keyword=1&key="), "http://h/f?keyword=1&key=***");
}

// --- the daemon's fetch thread --------------------------------------------

Plant ExamplePlant() {
  Config config;
  Diagnostics errors;
  EXPECT_TRUE(LoadConfig(kExamplePlantConfig.string(), &config, &errors));
  return config.plant;
}

class WeatherWorkerTest : public ::testing::Test {
 protected:
  WeatherFetchSettings Settings(int port) {
    WeatherFetchSettings s;
    s.store_path = (dir_ / "w.db").string();
    s.url = "http://127.0.0.1:" + std::to_string(port) +
            "/v1/forecast?latitude=47.358&longitude=16.128";
    s.plant = ExamplePlant();
    s.refresh_s = 3600.0;
    s.timeout_s = 2.0;
    s.first_retry_s = 0.2;
    return s;
  }
  LogFn Log() {
    return [this](int, const std::string& line) {
      std::lock_guard lock(mutex_);
      log_ += line + "\n";
    };
  }
  std::string LogText() {
    std::lock_guard lock(mutex_);
    return log_;
  }
  long long Rows() {
    std::string error;
    auto store = Store::Open((dir_ / "w.db").string(), &error);
    Series rows;
    if (!store || !store->ReadWeatherForecast(0, 4102444800, &rows, &error)) return -1;
    return static_cast<long long>(rows.size());
  }
  int CountLines(const std::string& needle) {
    const std::string text = LogText();
    int n = 0;
    for (std::size_t at = text.find(needle); at != std::string::npos;
         at = text.find(needle, at + 1)) {
      ++n;
    }
    return n;
  }

  ScratchDir dir_{"weather"};
  std::mutex mutex_;
  std::string log_;
};

// Server down at the start: one log line, retries with backoff; server up:
// the rows arrive with their source and one line says the server is back.
TEST_F(WeatherWorkerTest, FetchesAcrossAnOutageOfTheServer) {
  const int port = LoopbackHttpServer::FreePort();
  ASSERT_GT(port, 0);
  {
    std::string error;
    ASSERT_NE(Store::Open((dir_ / "w.db").string(), &error), nullptr) << error;
  }
  WeatherWorker worker(Settings(port), Log());
  worker.Start();
  ASSERT_TRUE(WaitFor(10, [&] { return CountLines("failed: unreachable") > 0; })) << LogText();
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // several retries
  EXPECT_EQ(CountLines("failed:"), 1) << "one line per change of state, not per retry\n"
                                      << LogText();
  EXPECT_EQ(Rows(), 0);

  LoopbackHttpServer server;
  server.SetAnswer("/v1/forecast", Recorded("open-meteo-hourly.json"));
  std::string error;
  ASSERT_TRUE(server.Start(port, &error)) << error;
  ASSERT_TRUE(WaitFor(20, [&] { return Rows() == 2880; })) << LogText();
  EXPECT_TRUE(WaitFor(5, [&] { return CountLines("answers again after") == 1; })) << LogText();
  EXPECT_TRUE(worker.TakeFresh());
  std::vector<std::string> sources;
  auto store = Store::Open((dir_ / "w.db").string(), &error);
  ASSERT_TRUE(store->ReadWeatherSources(0, 4102444800, &sources, &error)) << error;
  ASSERT_EQ(sources.size(), 1u);
  EXPECT_EQ(sources[0], "fetch http://127.0.0.1:" + std::to_string(port) +
                            "/v1/forecast?latitude=47.358&longitude=16.128 (Open-Meteo JSON, "
                            "hourly)");
  worker.Stop();
}

// A server answering with an unknown unit: the log names the field; no rows.
TEST_F(WeatherWorkerTest, WrongUnitsAreLoggedWithTheField) {
  LoopbackHttpServer server;
  server.SetAnswer("/v1/forecast", Recorded("open-meteo-wrong-units.json"));
  std::string error;
  ASSERT_TRUE(server.Start(0, &error)) << error;
  WeatherWorker worker(Settings(server.port()), Log());
  worker.Start();
  ASSERT_TRUE(WaitFor(10, [&] { return CountLines("not a usable forecast") > 0; })) << LogText();
  EXPECT_NE(LogText().find("hourly_units.wind_speed_10m = \"mph\": unknown unit"),
            std::string::npos)
      << LogText();
  EXPECT_EQ(Rows(), 0);
}

// An answer 3 h late puts June's evening light after sunset: the fetch logs
// each interval above its clear sky, writes the rows clipped and marks their
// source.
TEST_F(WeatherWorkerTest, IrradianceAboveItsClearSkyIsLoggedAndMarked) {
  LoopbackHttpServer server;
  LoopbackHttpServer::Answer late;
  late.body = Restamped(2024, 6, 1, 3);
  server.SetAnswer("/v1/forecast", late);
  std::string error;
  ASSERT_TRUE(server.Start(0, &error)) << error;
  WeatherWorker worker(Settings(server.port()), Log());
  worker.Start();
  ASSERT_TRUE(WaitFor(20, [&] { return Rows() == 2880; })) << LogText();
  worker.Stop();
  EXPECT_GE(CountLines("is more than its clear sky gives"), 1) << LogText();
  EXPECT_NE(LogText().find("weather: ghi_w_m2 2024-06-01T19:00:00Z .. 2024-06-01T20:00:00Z: "),
            std::string::npos)
      << LogText();
  auto store = Store::Open((dir_ / "w.db").string(), &error);
  std::vector<std::string> sources;
  ASSERT_TRUE(store->ReadWeatherSources(0, 4102444800, &sources, &error)) << error;
  ASSERT_EQ(sources.size(), 2u);
  EXPECT_EQ(sources[1], sources[0] + std::string(kAboveClearSkyMark)) << sources[0] << "\n"
                                                                      << sources[1];
}

// HTTP errors and a truncated body are failures with their reason, never rows.
TEST_F(WeatherWorkerTest, HttpErrorsAndCutBodiesWriteNothing) {
  LoopbackHttpServer server;
  LoopbackHttpServer::Answer unavailable;
  unavailable.status = 503;
  unavailable.body = "{\"error\":true,\"reason\":\"Too many concurrent requests\"}";
  server.SetAnswer("/v1/forecast", unavailable);
  std::string error;
  ASSERT_TRUE(server.Start(0, &error)) << error;
  WeatherWorker worker(Settings(server.port()), Log());
  worker.Start();
  ASSERT_TRUE(WaitFor(10, [&] {
    return CountLines("failed: HTTP error (HTTP 503: Too many concurrent requests)") > 0;
  })) << LogText();
  LoopbackHttpServer::Answer cut = Recorded("open-meteo-hourly.json");
  cut.truncate = true;
  server.SetAnswer("/v1/forecast", cut);
  ASSERT_TRUE(WaitFor(10, [&] { return CountLines("failed: transfer broken off") > 0; }))
      << LogText();
  EXPECT_EQ(Rows(), 0);
}

// Stop() does not wait for a server that takes its time.
TEST_F(WeatherWorkerTest, StopsPromptlyDuringASlowAnswer) {
  LoopbackHttpServer server;
  LoopbackHttpServer::Answer slow = Recorded("open-meteo-hourly.json");
  slow.delay_s = 30.0;
  server.SetAnswer("/v1/forecast", slow);
  std::string error;
  ASSERT_TRUE(server.Start(0, &error)) << error;
  WeatherFetchSettings settings = Settings(server.port());
  settings.timeout_s = 60.0;
  WeatherWorker worker(settings, Log());
  worker.Start();
  ASSERT_TRUE(WaitFor(10, [&] { return server.requests() > 0; }));
  const double start = WallNowS();
  worker.Stop();
  EXPECT_LT(WallNowS() - start, 1.5);
}

// --- real processes ---------------------------------------------------------

TEST(ImportWeatherCommand, ImportsEachFormatAndRefusesBadInputWithExit2) {
  ScratchDir dir("import-weather");
  fs::copy_file(kExamplePlantConfig, dir / "plant.toml");
  const auto hourly = RunPvtwin(dir.path(), "import-weather --config plant.toml --db w.db " +
                                                (kData / "open-meteo-hourly.json").string());
  EXPECT_EQ(hourly.exit_code, 0) << hourly.err;
  EXPECT_NE(hourly.err.find("wrote 2880 1-min rows into weather_forecast (2024-05-31T23:00:00Z .. "
                            "2024-06-02T23:00:00Z)"),
            std::string::npos)
      << hourly.err;
  const auto quarter = RunPvtwin(dir.path(), "import-weather --config plant.toml --db w.db " +
                                                 (kData / "open-meteo-15min.json").string());
  EXPECT_EQ(quarter.exit_code, 0) << quarter.err;
  EXPECT_NE(quarter.err.find("minutely_15.temperature_2m: 1 null values, read as missing"),
            std::string::npos)
      << quarter.err;
  const auto csv = RunPvtwin(dir.path(), "import-weather --config plant.toml --db w.db " +
                                             (kData / "weather.csv").string());
  EXPECT_EQ(csv.exit_code, 0) << csv.err;
  EXPECT_NE(csv.err.find("wrote 75 1-min rows"), std::string::npos) << csv.err;

  const auto units = RunPvtwin(dir.path(), "import-weather --config plant.toml --db w.db " +
                                               (kData / "open-meteo-wrong-units.json").string());
  EXPECT_EQ(units.exit_code, 2);
  EXPECT_NE(units.err.find("open-meteo-wrong-units.json: hourly_units.wind_speed_10m = \"mph\": "
                           "unknown unit: expected \"m/s\" or \"km/h\""),
            std::string::npos)
      << units.err;
  std::ofstream(dir / "cut.json") << ReadFile(kData / "open-meteo-hourly.json").substr(0, 900);
  const auto cut = RunPvtwin(dir.path(), "import-weather --config plant.toml --db w.db cut.json");
  EXPECT_EQ(cut.exit_code, 2);
  EXPECT_NE(cut.err.find("cut.json: truncated JSON"), std::string::npos) << cut.err;
}

// The rows of weather_forecast: time, ghi_w_m2, g_poa_w_m2 and source, as
// stored (not through Store, whose reads drop values beyond the limits).
struct StoredMinute {
  std::int64_t ts = 0;
  double ghi = 0.0, g_poa = 0.0;
  std::string source;
};
std::vector<StoredMinute> StoredMinutes(const fs::path& db_path) {
  std::vector<StoredMinute> rows;
  sqlite3* db = nullptr;
  if (sqlite3_open_v2(db_path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) == SQLITE_OK) {
    sqlite3_stmt* st = nullptr;
    if (sqlite3_prepare_v2(db,
                           "SELECT ts, ghi_w_m2, g_poa_w_m2, source FROM weather_forecast "
                           "ORDER BY ts",
                           -1, &st, nullptr) == SQLITE_OK) {
      while (sqlite3_step(st) == SQLITE_ROW) {
        const unsigned char* source = sqlite3_column_text(st, 3);
        rows.push_back({sqlite3_column_int64(st, 0), sqlite3_column_double(st, 1),
                        sqlite3_column_double(st, 2),
                        source ? reinterpret_cast<const char*>(source) : ""});
      }
    }
    sqlite3_finalize(st);
  }
  sqlite3_close(db);
  return rows;
}

// Every stored minute within its bound from physics (core/forecast/
// weather_resample.h): 2 × its clear sky (Ineichen & Perez, T_L = 3) +
// 50 W/m², the plane's clear sky the larger of the plane's and the
// horizontal's, never above the 2500 W/m² limit. Returns the rows whose
// source carries the mark.
std::size_t ExpectWithinClearSkyBounds(const fs::path& db_path) {
  const std::vector<StoredMinute> rows = StoredMinutes(db_path);
  EXPECT_EQ(rows.size(), 2880u);
  if (rows.empty()) return 0;
  const ClearSkyGrid g =
      MakeClearSkyGrid(ExamplePlant(), rows.front().ts, rows.back().ts + 60, 3.0);
  std::size_t marked = 0;
  for (const StoredMinute& r : rows) {
    const auto k = static_cast<std::size_t>((r.ts - rows.front().ts) / 60);
    const double ghi_bound = std::min(2500.0, 2.0 * g.clear_ghi_w_m2[k] + 50.0);
    const double poa_bound =
        std::min(2500.0, 2.0 * std::max(g.clear_poa_w_m2[k], g.clear_ghi_w_m2[k]) + 50.0);
    EXPECT_LE(r.ghi, ghi_bound + 1e-9) << r.ts;
    EXPECT_LE(r.g_poa, poa_bound + 1e-9) << r.ts;
    marked += r.source.ends_with(kAboveClearSkyMark) ? 1 : 0;
  }
  return marked;
}

// Irradiance a minute cannot hold (the recorded June answer stamped into
// December; the same answer 3 h late) is stored clipped to its clear-sky
// bound with a warning naming the interval, and exit code 0: the file is
// readable, only its time is suspect. The recorded answer as it is: no
// warning, nothing marked.
TEST(ImportWeatherCommand, IrradianceAboveItsClearSkyIsClippedAndNamed) {
  ScratchDir dir("import-weather-clear-sky");
  fs::copy_file(kExamplePlantConfig, dir / "plant.toml");
  std::ofstream(dir / "december.json") << Restamped(2025, 12, 20, 0);
  std::ofstream(dir / "late.json") << Restamped(2024, 6, 1, 3);

  const auto good = RunPvtwin(dir.path(), "import-weather --config plant.toml --db good.db " +
                                              (kData / "open-meteo-hourly.json").string());
  EXPECT_EQ(good.exit_code, 0) << good.err;
  EXPECT_EQ(good.err.find("warning"), std::string::npos) << good.err;
  EXPECT_EQ(ExpectWithinClearSkyBounds(dir / "good.db"), 0u);

  const auto december =
      RunPvtwin(dir.path(), "import-weather --config plant.toml --db december.db december.json");
  EXPECT_EQ(december.exit_code, 0) << december.err;
  // On 20 December the sun is up from about 06:40 to 15:05 UTC at the plant;
  // June's light, 03:00 to 19:00 UTC, does not fit into that day.
  EXPECT_NE(december.err.find("warning: ghi_w_m2 2025-12-20T"), std::string::npos) << december.err;
  EXPECT_NE(december.err.find("is more than its clear sky gives (clear sky "), std::string::npos)
      << december.err;
  EXPECT_NE(december.err.find("irradiance intervals above their clear sky stored clipped"),
            std::string::npos)
      << december.err;
  EXPECT_GT(ExpectWithinClearSkyBounds(dir / "december.db"), 0u);

  const auto late =
      RunPvtwin(dir.path(), "import-weather --config plant.toml --db late.db late.json");
  EXPECT_EQ(late.exit_code, 0) << late.err;
  EXPECT_NE(late.err.find("warning: ghi_w_m2 2024-06-01T19:00:00Z .. 2024-06-01T20:00:00Z: "),
            std::string::npos)
      << late.err;
  EXPECT_GT(ExpectWithinClearSkyBounds(dir / "late.db"), 0u);
}

// Without --config the plant comes from the store, which the daemon fills.
TEST(ImportWeatherCommand, TakesThePlantFromTheStore) {
  ScratchDir dir("import-weather-db");
  const std::string file = (kData / "open-meteo-hourly.json").string();
  const auto bare = RunPvtwin(dir.path(), "import-weather --db w.db " + file);
  EXPECT_EQ(bare.exit_code, 2);
  EXPECT_NE(bare.err.find("no such database"), std::string::npos) << bare.err;
  std::string error;
  {
    auto store = Store::Open((dir / "w.db").string(), &error);
    ASSERT_NE(store, nullptr) << error;
  }
  const auto empty = RunPvtwin(dir.path(), "import-weather --db w.db " + file);
  EXPECT_EQ(empty.exit_code, 2);
  EXPECT_NE(empty.err.find("the store holds no plant yet"), std::string::npos) << empty.err;
  {
    auto store = Store::Open((dir / "w.db").string(), &error);
    ASSERT_TRUE(store->WritePlantConfig(PlantKeyValues(ExamplePlant()), &error)) << error;
  }
  const auto ok = RunPvtwin(dir.path(), "import-weather --db w.db " + file);
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_NE(ok.err.find("wrote 2880 1-min rows"), std::string::npos) << ok.err;
}

// The real daemon polling the simulated plant, its weather server down at the
// start and up later: the log says so once, the rows arrive, and the next
// forecast's inputs name the fetched source.
class DaemonWeatherFetch : public ::testing::Test {
 protected:
  static constexpr double kSpeed = 120.0;
  // 2024-06-01 08:00 UTC: the recorded answers cover 2024-05-31 23:00 to
  // 2024-06-02 23:00.
  static constexpr std::int64_t kMorning = 1717228800;

  void SetUp() override {
    fs::copy_file(kExamplePlantConfig, dir_ / "sim.toml");
    const auto exported = RunPvtwin(
        dir_.path(), "sim --config sim.toml --export history.csv --days 14 --step 60 --start " +
                         std::to_string(kMorning - 14 * 86400));
    ASSERT_EQ(exported.exit_code, 0) << exported.err;
    const auto imported =
        RunPvtwin(dir_.path(), "import --config sim.toml --csv history.csv --db " + Db());
    ASSERT_EQ(imported.exit_code, 0) << imported.err;
    anchor_ = WallNowS();
    std::string error;
    ASSERT_TRUE(
        sim_.StartPiped({PVTWIN_BINARY, "sim", "--config", (dir_ / "sim.toml").string(),
                         "--ephemeral-ports", "--speed", std::to_string(kSpeed), "--start",
                         std::to_string(kMorning), "--wall-anchor", std::to_string(anchor_)},
                        (dir_ / "sim.log").string(), &error))
        << error;
    std::vector<std::string> lines;
    ASSERT_TRUE(sim_.ReadUntil("ready", 20.0, &lines)) << ReadFile(dir_ / "sim.log");
    port_ = LoopbackHttpServer::FreePort();
    ASSERT_GT(port_, 0);
    DaemonSettings settings;
    settings.db_path = Db();
    settings.weather_url = "http://127.0.0.1:" + std::to_string(port_) +
                           "/v1/forecast?latitude={lat}&longitude={lon}&hourly=shortwave_radiation";
    settings.weather_refresh_min = 5;
    settings.weather_timeout_s = timeout_s_;
    std::string text;
    ASSERT_TRUE(EditConfig(ReadFile(kExamplePlantConfig), ParseListeningLines(lines), settings,
                           &text, &error))
        << error;
    std::ofstream(dir_ / "pvtwin.toml") << text;
  }
  void TearDown() override {
    daemon_.Stop(SIGTERM, 10.0);
    sim_.SendLine("quit");
    sim_.Stop(0, 5.0);
  }
  std::string Db() const { return (dir_ / "pvtwin.db").string(); }
  std::string DaemonLog() const { return ReadFile(dir_ / "daemon.log"); }
  std::string Sql(const std::string& sql) const {
    sqlite3* db = nullptr;
    std::string result;
    if (sqlite3_open_v2(Db().c_str(), &db, SQLITE_OPEN_READONLY, nullptr) == SQLITE_OK) {
      sqlite3_busy_timeout(db, 5000);
      sqlite3_stmt* st = nullptr;
      if (sqlite3_prepare_v2(db, sql.c_str(), -1, &st, nullptr) == SQLITE_OK &&
          sqlite3_step(st) == SQLITE_ROW && sqlite3_column_text(st, 0) != nullptr) {
        result = reinterpret_cast<const char*>(sqlite3_column_text(st, 0));
      }
      sqlite3_finalize(st);
    }
    sqlite3_close(db);
    return result;
  }

  ScratchDir dir_{"weather-e2e"};
  double timeout_s_ = 5.0;  // [forecast] weather_timeout_s
  double anchor_ = 0.0;
  int port_ = 0;
  ChildProcess sim_;
  ChildProcess daemon_;
};

TEST_F(DaemonWeatherFetch, FetchesAcrossAnOutageAndNamesTheSourceInTheForecast) {
  std::string error;
  ASSERT_TRUE(daemon_.Start({PVTWIN_BINARY, "run", "--config", (dir_ / "pvtwin.toml").string(),
                             "--speed", std::to_string(kSpeed), "--sim-start",
                             std::to_string(kMorning), "--wall-anchor", std::to_string(anchor_)},
                            (dir_ / "daemon.log").string(), &error))
      << error;
  // Server down: one clear line, polling goes on.
  ASSERT_TRUE(WaitFor(30, [&] {
    return DaemonLog().find("weather: fetching http://127.0.0.1:" + std::to_string(port_) +
                            "/v1/forecast?latitude=47.358&longitude=16.128&hourly="
                            "shortwave_radiation failed: unreachable") != std::string::npos;
  })) << DaemonLog();
  const std::string live = "SELECT COUNT(*) FROM sample_5s WHERE ts >= " + std::to_string(kMorning);
  ASSERT_TRUE(WaitFor(30, [&] { return Sql(live) != "" && std::stoll(Sql(live)) >= 12; }))
      << DaemonLog();
  EXPECT_EQ(Sql("SELECT COUNT(*) FROM weather_forecast"), "0");

  // Server up: the rows arrive, the log says it is back, and the next
  // forecast names the fetched source.
  LoopbackHttpServer server;
  server.SetAnswer("/v1/forecast", Recorded("open-meteo-hourly.json"));
  ASSERT_TRUE(server.Start(port_, &error)) << error;
  ASSERT_TRUE(WaitFor(90, [&] { return Sql("SELECT COUNT(*) FROM weather_forecast") == "2880"; }))
      << DaemonLog();
  // The worker logs the recovery after it has written the rows.
  EXPECT_TRUE(WaitFor(10, [&] {
    return DaemonLog().find("answers again after") != std::string::npos;
  })) << DaemonLog();
  EXPECT_EQ(Sql("SELECT DISTINCT source FROM weather_forecast"),
            "fetch http://127.0.0.1:" + std::to_string(port_) +
                "/v1/forecast?latitude=47.358&longitude=16.128&hourly=shortwave_radiation "
                "(Open-Meteo JSON, hourly)");
  const std::string with_source =
      "SELECT inputs FROM forecast WHERE inputs LIKE '%weather_forecast source: fetch "
      "http://127.0.0.1:" +
      std::to_string(port_) + "%' LIMIT 1";
  ASSERT_TRUE(WaitFor(120, [&] { return !Sql(with_source).empty(); })) << DaemonLog();
  const std::string inputs = Sql(with_source);
  EXPECT_NE(inputs.find("t_amb_c=weather_forecast"), std::string::npos) << inputs;
  EXPECT_NE(inputs.find("g_poa_w_m2=weather_forecast"), std::string::npos) << inputs;

  // SIGTERM is served well within systemd's stop timeout.
  const double start = WallNowS();
  EXPECT_EQ(daemon_.Stop(SIGTERM, UnitStopTimeoutS()), 0) << DaemonLog();
  EXPECT_LT(WallNowS() - start, UnitStopTimeoutS() / 2) << DaemonLog();
}

// A weather server that takes its time (the fetch's limit is 2 min, the
// answer comes after 1 min) does not hold up SIGTERM.
class DaemonWeatherFetchSlowServer : public DaemonWeatherFetch {
 protected:
  DaemonWeatherFetchSlowServer() { timeout_s_ = 120.0; }
};

TEST_F(DaemonWeatherFetchSlowServer, StopsPromptlyWhileTheServerIsSlow) {
  LoopbackHttpServer server;
  LoopbackHttpServer::Answer slow = Recorded("open-meteo-hourly.json");
  slow.delay_s = 60.0;
  server.SetAnswer("/v1/forecast", slow);
  std::string error;
  ASSERT_TRUE(server.Start(port_, &error)) << error;
  ASSERT_TRUE(daemon_.Start({PVTWIN_BINARY, "run", "--config", (dir_ / "pvtwin.toml").string(),
                             "--speed", std::to_string(kSpeed), "--sim-start",
                             std::to_string(kMorning), "--wall-anchor", std::to_string(anchor_)},
                            (dir_ / "daemon.log").string(), &error))
      << error;
  ASSERT_TRUE(WaitFor(30, [&] { return server.requests() > 0; })) << DaemonLog();
  const double start = WallNowS();
  EXPECT_EQ(daemon_.Stop(SIGTERM, UnitStopTimeoutS()), 0) << DaemonLog();
  EXPECT_LT(WallNowS() - start, UnitStopTimeoutS() / 2) << DaemonLog();
}

}  // namespace
}  // namespace pvtwin
