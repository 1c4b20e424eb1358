#include "io/files/params_json.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

namespace pvtwin {

namespace {

// 1-based line of a byte offset in text.
int LineOf(const std::string& text, std::size_t byte) {
  int line = 1;
  for (std::size_t i = 0; i < byte && i < text.size(); ++i) line += text[i] == '\n';
  return line;
}

// Line on which "key" first appears (for messages about a parsed value).
int LineOfKey(const std::string& text, const std::string& key) {
  const std::size_t pos = text.find("\"" + key + "\"");
  return pos == std::string::npos ? 0 : LineOf(text, pos);
}

}  // namespace

bool ParseParamsJson(const std::string& text, const std::string& path, const Plant& plant,
                     ParamsFile* out, Diagnostics* errors) {
  const std::size_t errors_before = errors->size();
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    errors->push_back({path, LineOf(text, e.byte == 0 ? 0 : e.byte - 1), "", "",
                       std::string("malformed JSON: ") + e.what()});
    return false;
  }
  if (!doc.is_object()) {
    errors->push_back({path, 1, "", "", "expected a JSON object of parameter names to numbers"});
    return false;
  }
  ParamsFile result;
  result.values = StartParams(plant);
  const nlohmann::json* params = &doc;
  if (doc.contains("params")) {
    params = &doc["params"];
    if (!params->is_object()) {
      errors->push_back({path, LineOfKey(text, "params"), "params", "", "expected an object"});
      return false;
    }
  }
  if (doc.contains("variant")) {
    if (doc["variant"].is_string()) {
      result.variant = doc["variant"].get<std::string>();
    } else {
      errors->push_back({path, LineOfKey(text, "variant"), "variant", doc["variant"].dump(),
                         "expected a string"});
    }
  }
  for (const auto& [key, value] : params->items()) {
    if (params == &doc && (key == "variant" || key == "fit")) continue;
    const std::optional<Param> p = ParamFromName(key);
    if (!p) {
      errors->push_back({path, LineOfKey(text, key), key, value.dump(), "unknown parameter"});
      continue;
    }
    if (!value.is_number() || !std::isfinite(value.get<double>())) {
      errors->push_back({path, LineOfKey(text, key), key, value.dump(), "expected a finite number"});
      continue;
    }
    result.values[static_cast<std::size_t>(*p)] = value.get<double>();
    result.given.set(static_cast<std::size_t>(*p));
  }
  if (errors->size() != errors_before) return false;
  *out = result;
  return true;
}

bool ReadParamsJson(const std::string& path, const Plant& plant, ParamsFile* out,
                    Diagnostics* errors) {
  std::ifstream in(path);
  if (!in) {
    errors->push_back({path, 0, "", "", std::string("cannot open: ") + std::strerror(errno)});
    return false;
  }
  std::stringstream buffer;
  buffer << in.rdbuf();
  return ParseParamsJson(buffer.str(), path, plant, out, errors);
}

std::string FormatParamsJson(const std::string& variant, const ParamVector& values,
                             const std::bitset<kNumParams>& only, const std::string& fit_json) {
  nlohmann::ordered_json doc;
  doc["variant"] = variant;
  nlohmann::ordered_json params = nlohmann::ordered_json::object();
  for (const ParamInfo& info : kParamTable) {
    const auto i = static_cast<std::size_t>(info.param);
    if (only.none() || only.test(i)) params[std::string(info.name)] = values[i];
  }
  doc["params"] = params;
  if (!fit_json.empty()) doc["fit"] = nlohmann::ordered_json::parse(fit_json);
  return doc.dump(2) + "\n";
}

bool WriteTextFileAtomically(const std::string& path, const std::string& text,
                             std::string* error) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << text;
    out.flush();
    if (!out) {
      *error = "cannot write " + tmp + ": " + std::strerror(errno);
      return false;
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    *error = "cannot rename " + tmp + " to " + path + ": " + std::strerror(errno);
    std::remove(tmp.c_str());
    return false;
  }
  return true;
}

}  // namespace pvtwin
