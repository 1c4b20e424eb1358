// The reload job of the Service (service_internal.h): on SIGHUP the config
// file is read again; a config with errors is refused and the running one
// stays; otherwise every key that changed is logged (old → new), with the
// ones a reload cannot apply named (kNeedsRestart), and systemd's STATUS=
// says how it went until the next health line replaces it.
#include <string_view>

#include "config/config_diff.h"
#include "daemon/service/notify.h"
#include "daemon/service/service_internal.h"
#include "io/platform/log.h"

namespace pvtwin::service_detail {

namespace {

// What a reload does not apply, as LoadAndApplyConfig treats it: the store,
// the poller and the upload keep the file, connections and settings they
// were started with; the 1-min aggregation (the store's options) and the
// poller keep the plant values they were given. An empty key: the whole
// section.
struct NeedsRestart {
  std::string_view section;
  std::string_view key;
  std::string_view why;
};
constexpr NeedsRestart kNeedsRestart[] = {
    {"storage", "", "the store stays open"},
    {"poll", "", "the poller keeps its period"},
    {"modbus.device", "", "the poller keeps its register map"},
    {"modbus.point", "", "the poller keeps its register map"},
    {"upload", "", "the upload keeps its server"},
    {"plant", "fluid_cp_j_kgk", "the 1-min aggregation keeps the old value"},
    {"plant", "area_m2", "the 1-min aggregation and the poller's limits keep the old value"},
    {"plant", "fluid_density_kg_m3", "the poller's volume flows keep the old value"},
};

const NeedsRestart* RestartRuleOf(const ConfigChange& change) {
  for (const NeedsRestart& rule : kNeedsRestart) {
    if (rule.section == change.section && (rule.key.empty() || rule.key == change.key)) {
      return &rule;
    }
  }
  return nullptr;
}

// A value for a log line: long ones (a URL) shortened in the middle.
std::string Shortened(const std::string& value) {
  constexpr std::size_t kMax = 48;
  if (value.size() <= kMax) return value;
  return value.substr(0, kMax / 2) + "…" + value.substr(value.size() - kMax / 2 + 2);
}

// Change lines logged at most; the rest are counted.
constexpr std::size_t kMaxChangeLines = 20;

}  // namespace

std::string Service::LogConfigChanges(const std::string& old_text, const std::string& new_text) {
  std::vector<ConfigChange> changes;
  std::string error;
  if (!DiffConfigTexts(old_text, new_text, &changes, &error)) {
    // Both texts were parsed before; only a file changed between two reads
    // could get here.
    LogToStderr(kWarning, "reload: the changed keys could not be listed: " + error);
    return "keys changed (not listed)";
  }
  if (changes.empty()) {
    LogToStderr(kInfo, "reload: no change");
    return "no change";
  }
  std::vector<std::string> restart;
  for (std::size_t i = 0; i < changes.size(); ++i) {
    const ConfigChange& c = changes[i];
    const NeedsRestart* rule = RestartRuleOf(c);
    if (rule != nullptr) restart.push_back(c.Name());
    if (i >= kMaxChangeLines) continue;
    std::string line = "reload: " + c.Name() + " " + Shortened(c.old_value) + " → " +
                       Shortened(c.new_value);
    if (rule != nullptr) line += "; needs a restart (" + std::string(rule->why) + ")";
    LogToStderr(rule != nullptr ? kWarning : kInfo, line);
  }
  if (changes.size() > kMaxChangeLines) {
    LogToStderr(kInfo, "reload: and " + std::to_string(changes.size() - kMaxChangeLines) +
                           " more changed keys");
  }
  std::string summary = std::to_string(changes.size()) +
                        (changes.size() == 1 ? " key changed" : " keys changed");
  if (!restart.empty()) {
    summary += ", " + std::to_string(restart.size()) +
               (restart.size() == 1 ? " needs a restart: " : " need a restart: ") + restart[0];
    if (restart.size() > 1) summary += " …";
  }
  LogToStderr(restart.empty() ? kInfo : kWarning, "reload: " + summary);
  return summary;
}

void Service::Reload() {
  NotifyReloading();
  LogToStderr(kInfo, "SIGHUP: reloading " + options_.config_path);
  const int status_min = config_.log.status_min;
  std::string outcome;
  if (!LoadAndApplyConfig(false, &outcome)) {
    const std::string line = "reload failed: " + outcome + "; running with the previous config";
    LogToStderr(kErr, line);
    NotifyReady(line);
    return;
  }
  RecordPlant();
  UpdateWeatherFetch();
  if (config_.log.status_min != status_min) ArmHealthReport();
  NotifyReady("reloaded: " + outcome);
}

}  // namespace pvtwin::service_detail
