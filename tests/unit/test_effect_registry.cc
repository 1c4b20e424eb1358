// The effect registry (core/effects/registry.h): every module is complete —
// a name of doc/contracts.md's vocabulary, a paragraph of physics with a source,
// parameters whose bounds contain their start and truth values, a signature
// and an advice sentence — and the registry holds the whole vocabulary once.
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <string_view>

#include "core/effects/effects.h"
#include "core/model/variant.h"

namespace pvtwin {
namespace {

// doc/contracts.md's effect vocabulary, spelled and ordered as there.
constexpr std::string_view kVocabulary[] = {"capacitance",     "second_node",  "wind",
                                            "sky_radiation",   "iam",          "flow_dependent_u",
                                            "transport_delay", "pv_clipping",  "shading",
                                            "soiling",         "clock_offset", "irradiance_bias"};

TEST(EffectRegistry, HoldsTheVocabularyOnceInItsOrder) {
  const auto& registry = EffectRegistry();
  ASSERT_EQ(registry.size(), std::size(kVocabulary));
  for (std::size_t i = 0; i < registry.size(); ++i) {
    EXPECT_EQ(registry[i]->name, kVocabulary[i]);
    EXPECT_EQ(FindEffect(kVocabulary[i]), registry[i]);
  }
  EXPECT_EQ(FindEffect("none"), nullptr);
  EXPECT_EQ(FindEffect("unknown"), nullptr);
}

TEST(EffectRegistry, EveryModuleIsComplete) {
  for (const EffectModule* m : EffectRegistry()) {
    const std::string name(m->name);
    EXPECT_GT(m->physics.size(), 100u) << name;
    EXPECT_FALSE(m->source.empty()) << name;
    EXPECT_FALSE(m->signature.empty()) << name;
    EXPECT_NE(m->signature_values, nullptr) << name;
    // One sentence: ends with a full stop, none before.
    ASSERT_FALSE(m->advice.empty()) << name;
    EXPECT_EQ(m->advice.back(), '.') << name;
    EXPECT_EQ(m->advice.find(". "), std::string_view::npos) << name;
    for (Param p : m->params) {
      const ParamInfo& info = Info(p);
      EXPECT_LE(info.lower, info.start) << name << " " << info.name;
      EXPECT_GE(info.upper, info.start) << name << " " << info.name;
      EXPECT_FALSE(info.unit.empty()) << name << " " << info.name;
      EXPECT_FALSE(info.symbol.empty()) << name << " " << info.name;
    }
    for (const auto& [param, value] : m->typical_truth) {
      const ParamInfo& info = Info(param);
      EXPECT_GE(value, info.lower) << name << " " << info.name;
      EXPECT_LE(value, info.upper) << name << " " << info.name;
    }
    // A module reaches the model either through the paper's letters or
    // through its own extension, named like the module.
    if (m->extension != nullptr) {
      EXPECT_EQ(m->extension->name, m->name);
    } else {
      EXPECT_NE(m->in_spec, nullptr) << name;
      EXPECT_NE(m->add_to_spec, nullptr) << name;
    }
  }
}

TEST(EffectRegistry, ExtensionsHaveDistinctVariantOrders) {
  std::set<int> orders;
  for (const EffectModule* m : EffectRegistry()) {
    if (m->extension == nullptr) continue;
    EXPECT_TRUE(orders.insert(m->extension->variant_order).second) << m->name;
    // Every parameter the extension's equations use is one of the module's
    // parameters.
    for (Param p : m->extension->params) {
      bool listed = false;
      for (Param q : m->params) listed = listed || q == p;
      EXPECT_TRUE(listed) << m->name << " " << Info(p).name;
    }
  }
}

}  // namespace
}  // namespace pvtwin
