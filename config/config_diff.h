// What changed between two texts of a config file, key by key, for the
// daemon's reload log (daemon/service/service_reload.cc). Values are compared
// as written (the TOML text of each value), so a key added with its default
// value is a change; a key only in one text has "(not set)" on the other
// side. Arrays of tables ([[modbus.point]]) are compared entry by entry, in
// file order.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace pvtwin {

struct ConfigChange {
  std::string section;  // "forecast", "modbus.point"; "" for a top-level key
  int entry = 0;        // 1-based entry of an array of tables; 0 for a table
  std::string key;
  std::string old_value;  // as written, or kNotSet
  std::string new_value;

  static constexpr std::string_view kNotSet = "(not set)";
  // "[forecast] refresh_min", "[[modbus.point]] #3 address".
  std::string Name() const;
};

// The changes from old_text to new_text, ordered by section, entry and key.
// False with *error when either text is not TOML.
bool DiffConfigTexts(std::string_view old_text, std::string_view new_text,
                     std::vector<ConfigChange>* changes, std::string* error);

}  // namespace pvtwin
