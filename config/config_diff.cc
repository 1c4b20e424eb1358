#include "config/config_diff.h"

#include <map>
#include <sstream>
#include <toml++/toml.h>
#include <tuple>

#include "config/toml_reader.h"

namespace pvtwin {

namespace {

using config_detail::SourceText;
using Where = std::tuple<std::string, int, std::string>;  // section, entry, key
using Flat = std::map<Where, std::string>;

bool IsArrayOfTables(const toml::node& node) {
  const toml::array* array = node.as_array();
  return array != nullptr && !array->empty() && array->is_array_of_tables();
}

// The value as written when it sits on one line, else as toml++ prints it.
std::string ValueText(const toml::node& node, const SourceText& source) {
  std::string text = source.Quote(node.source());
  if (!text.empty()) return text;
  std::ostringstream out;
  node.visit([&](const auto& n) { out << n; });
  return out.str();
}

void Flatten(const toml::table& table, const std::string& section, int entry,
             const SourceText& source, Flat* out) {
  for (const auto& item : table) {
    const std::string key(item.first.str());
    const toml::node& node = item.second;
    const std::string inner = section.empty() ? key : section + "." + key;
    if (const toml::table* sub = node.as_table()) {
      Flatten(*sub, inner, 0, source, out);
    } else if (IsArrayOfTables(node)) {
      int n = 0;
      for (const toml::node& element : *node.as_array()) {
        Flatten(*element.as_table(), inner, ++n, source, out);
      }
    } else {
      (*out)[Where{section, entry, key}] = ValueText(node, source);
    }
  }
}

bool FlattenText(std::string_view text, Flat* out, std::string* error) {
  try {
    const toml::table root = toml::parse(text);
    Flatten(root, "", 0, SourceText(text), out);
    return true;
  } catch (const toml::parse_error& e) {
    *error = std::string(e.description());
    return false;
  }
}

}  // namespace

std::string ConfigChange::Name() const {
  if (section.empty()) return key;
  if (entry == 0) return "[" + section + "] " + key;
  return "[[" + section + "]] #" + std::to_string(entry) + " " + key;
}

bool DiffConfigTexts(std::string_view old_text, std::string_view new_text,
                     std::vector<ConfigChange>* changes, std::string* error) {
  Flat before, after;
  if (!FlattenText(old_text, &before, error) || !FlattenText(new_text, &after, error)) return false;
  changes->clear();
  const auto add = [&](const Where& where, const std::string& was, const std::string& now) {
    changes->push_back({std::get<0>(where), std::get<1>(where), std::get<2>(where), was, now});
  };
  // Both maps are ordered by (section, entry, key): one merge pass.
  auto b = before.begin();
  auto a = after.begin();
  const std::string not_set(ConfigChange::kNotSet);
  while (b != before.end() || a != after.end()) {
    if (a == after.end() || (b != before.end() && b->first < a->first)) {
      add(b->first, b->second, not_set);
      ++b;
    } else if (b == before.end() || a->first < b->first) {
      add(a->first, not_set, a->second);
      ++a;
    } else {
      if (b->second != a->second) add(b->first, b->second, a->second);
      ++b;
      ++a;
    }
  }
  return true;
}

}  // namespace pvtwin
