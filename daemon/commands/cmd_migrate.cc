// pvtwin migrate: upgrade a store to this pvtwin's schema, for the verbs that
// only read it (export, diagnose --db) and never migrate.
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "daemon/commands/commands.h"
#include "daemon/commands/inputs.h"
#include "daemon/service/store_cli.h"

namespace pvtwin::cli {

namespace {

struct MigrateArgs {
  std::string config;
  std::string db;
};

int Migrate(const MigrateArgs& a) {
  if (a.config.empty() && a.db.empty()) {
    std::cerr << "migrate: give --db (the store) or --config (its [storage] path)\n";
    return kExitBadInput;
  }
  Config config;
  if (!a.config.empty() && !LoadConfigOrReport(a.config, &config)) return kExitBadInput;
  const std::string path = a.db.empty() ? config.storage.path : a.db;
  if (!std::filesystem::exists(path)) {
    std::cerr << path << ": no such database\n";
    return kExitBadInput;
  }
  std::unique_ptr<Store> store;
  StoreOptions options = StoreOptionsFor(config);
  options.log = nullptr;  // said below, on stdout
  if (!OpenStoreOrReport(path, options, &store)) return kExitRuntime;
  const Store::SchemaUpgrade& upgrade = store->upgrade();
  if (upgrade.from_version != 0) {
    std::cout << path << ": migrated store schema " << upgrade.from_version << " → "
              << upgrade.to_version << " (backup: " << upgrade.backup_path << ")\n";
  }
  std::cout << path << ": store schema " << kStoreSchemaVersion << "\n";
  return kExitOk;
}

}  // namespace

void RegisterMigrate(CLI::App& app) {
  auto args = std::make_shared<MigrateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "migrate",
      "Upgrade the SQLite store to this pvtwin's schema (the daemon does it when it starts;\n"
      "export and diagnose --db only read and refuse an older store), after copying it to\n"
      "<db>.schema-v<old>.bak. Needs write access: run it as the service user\n"
      "(sudo -u pvtwin). Exit 0 upgraded or already current,\n"
      "1 the store cannot be opened or upgraded, 2 bad input.");
  cmd->add_option("--config", args->config, "TOML config whose [storage] path is the store");
  cmd->add_option("--db", args->db, "SQLite file to use instead of [storage] path");
  cmd->callback([args] { SetExitCode(Migrate(*args)); });
}

}  // namespace pvtwin::cli
