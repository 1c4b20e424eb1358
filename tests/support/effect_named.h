// Tests name effects by their vocabulary names; this looks the module up.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <string_view>

#include "core/effects/registry.h"

namespace pvtwin::testing {

inline const EffectModule& EffectNamed(std::string_view name) {
  const EffectModule* m = FindEffect(name);
  if (m == nullptr) {
    ADD_FAILURE() << "no effect module named " << name;
    std::abort();
  }
  return *m;
}

}  // namespace pvtwin::testing
