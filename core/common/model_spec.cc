#include "core/common/model_spec.h"

#include <algorithm>

namespace pvtwin {

bool ModelSpec::Has(const ModelExtension& e) const {
  return std::find(extensions.begin(), extensions.end(), &e) != extensions.end();
}

void ModelSpec::Add(const ModelExtension& e) {
  if (Has(e)) return;
  const auto at = std::find_if(extensions.begin(), extensions.end(), [&e](const ModelExtension* x) {
    // Two forms of one effect share a place: then by name, so that the
    // canonical name does not depend on the order of adding.
    return x->variant_order > e.variant_order ||
           (x->variant_order == e.variant_order && x->name > e.name);
  });
  extensions.insert(at, &e);
}

void ModelSpec::Remove(const ModelExtension& e) {
  extensions.erase(std::remove(extensions.begin(), extensions.end(), &e), extensions.end());
}

bool ModelSpec::ReadsWind() const {
  return wind_paper || std::any_of(extensions.begin(), extensions.end(),
                                   [](const ModelExtension* e) { return e->reads_wind; });
}

std::string ModelSpec::Name() const {
  std::string name = nodes == 1 ? "1N" : "2N";
  if (nodes == 1) {
    if (c_pv) name += "1C";
  } else if (c_pv && c_coll) {
    name += "2C";
  } else if (c_pv) {
    name += "1Cpv";
  } else if (c_coll) {
    name += "1Ccol";
  }
  if (wind_paper) name += "w";
  if (sky) name += "r";
  if (iam) name += "I";
  for (const ModelExtension* e : extensions) name += "+" + std::string(e->name);
  return name;
}

}  // namespace pvtwin
