// Opening the SQLite store from a subcommand (import, export, bench).
#pragma once

#include <memory>
#include <string>

#include "config/plant_config.h"
#include "io/store/store.h"

namespace pvtwin::cli {

// Store options from the config: poll period and fluid c_p for aggregation.
StoreOptions StoreOptionsFor(const Config& config);

// Opens (creating and migrating) the store at path; reports a failure on
// stderr and returns false.
bool OpenStoreOrReport(const std::string& path, const StoreOptions& options,
                       std::unique_ptr<Store>* store);

// Opens the existing store at path for reading only (Store::OpenReadOnly:
// never creates, migrates or writes it); reports a failure on stderr and
// returns false.
bool OpenStoreReadOnlyOrReport(const std::string& path, const StoreOptions& options,
                               std::unique_ptr<Store>* store);

}  // namespace pvtwin::cli
