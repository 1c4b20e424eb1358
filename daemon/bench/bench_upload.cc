// pvtwin-bench upload: the upload of a 30-day backlog of 1-min rows (43 200
// rows of measurement_1min, synthetic 2N1Ccolwr truth with sensor noise)
// into a PostgreSQL server that the bench starts itself in a temporary
// directory (tests/support/pg_scratch_server.h, unix socket only). The uploader runs
// in this process as it runs in the daemon's upload thread, so the process
// CPU time printed is the daemon's share; the server's own CPU is not in it.
//
// Printed per batch size: the time to queue the backlog (the triggers'
// first install on an existing store), then rows, wall time, rows/s and
// CPU seconds (user + system) of the upload itself.

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/synth/synthetic_plant.h"
#include "daemon/bench/bench.h"
#include "tests/support/pg_scratch_server.h"
#include "io/store/store.h"
#include "io/fleet/upload.h"

namespace pvtwin::cli {

namespace {

constexpr int kBacklogDays = 30;

// One upload of the backlog with batch_rows into a fresh database.
void RunOne(const PgScratchServer& server, const Series& minutes, int batch_rows,
            const std::filesystem::path& dir) {
  const std::string db_name = "bench" + std::to_string(batch_rows);
  server.Text("CREATE DATABASE " + db_name);
  const std::string path = (dir / (db_name + ".db")).string();
  std::string error;
  {
    std::unique_ptr<Store> store = Store::Open(path, &error);
    if (!store || !store->WriteMinutes(minutes, &error)) {
      std::printf("  store error: %s\n", error.c_str());
      return;
    }
  }
  UploadSettings settings;
  settings.store_path = path;
  settings.url = server.Conninfo(db_name);
  settings.password_file = (dir / "pgpassword").string();
  settings.plant_id = "bench";
  settings.batch_rows = batch_rows;
  auto start = std::chrono::steady_clock::now();
  std::unique_ptr<Uploader> uploader = Uploader::Open(settings, &error);
  if (!uploader) {
    std::printf("  upload error: %s\n", error.c_str());
    return;
  }
  const double queue_s = SecondsSince(start);
  start = std::chrono::steady_clock::now();
  const double cpu_start = SelfCpuSeconds();
  std::int64_t total = 0;
  bool more = true;
  while (more) {
    std::int64_t rows = 0;
    PgError pg_error;
    if (!uploader->UploadBatches(&rows, &more, &pg_error)) {
      std::printf("  upload error: %s\n", pg_error.message.c_str());
      return;
    }
    total += rows;
  }
  const double wall_s = SecondsSince(start);
  const double cpu_s = SelfCpuSeconds() - cpu_start;
  std::printf("  %10d %10.2f %8lld %10.2f %10.0f %10.2f %7.0f %%\n", batch_rows, queue_s,
              static_cast<long long>(total), wall_s, static_cast<double>(total) / wall_s, cpu_s,
              100.0 * cpu_s / wall_s);
}

}  // namespace

void BenchUpload(std::uint64_t seed) {
  PgScratchServer server;
  std::string error;
  if (!server.Start(&error)) {
    std::printf("upload: no PostgreSQL to measure against: %s\n", error.c_str());
    return;
  }
  std::ofstream(server.dir() / "pgpassword") << server.password() << "\n";
  const Plant plant = DesignExamplePlant();
  WeatherOptions weather;
  weather.num_days = kBacklogDays;
  weather.step_s = 60.0;
  weather.seed = seed;
  ModelSpec spec;
  ParseVariant("2N1Ccolwr", &spec, &error);
  const Series minutes = MakeSyntheticPlantData(plant, weather, spec, ReferenceTruthParams(plant),
                                                RealisticSensorNoise(seed));
  std::printf(
      "upload: %d-day backlog of measurement_1min (%zu rows), seed %llu, into a local "
      "PostgreSQL (unix socket, fsync off); CPU = this process (the uploader), not the server\n",
      kBacklogDays, minutes.size(), static_cast<unsigned long long>(seed));
  std::printf("  %10s %10s %8s %10s %10s %10s %9s\n", "batch_rows", "queue (s)", "rows",
              "upload (s)", "rows/s", "CPU (s)", "CPU");
  for (const int batch_rows : {1000, 5000}) RunOne(server, minutes, batch_rows, server.dir());
}

}  // namespace pvtwin::cli
