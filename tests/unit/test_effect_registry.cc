// The effect registry (core/effects/registry.h): it is the one list of
// effects (core/common/effect_list.h) with the parameter slots the list of
// parameters assigns to each, doc/contracts.md's vocabulary is that list,
// and every module is complete —
// a name of the vocabulary, a paragraph of physics with a source,
// parameters whose bounds contain their start and truth values, a signature
// and an advice sentence — and the registry holds the whole vocabulary once.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "core/effects/effects.h"
#include "core/model/variant.h"
#include "tests/support/files.h"

namespace pvtwin {
namespace {

// doc/contracts.md's vocabulary paragraph: the effect names in backquotes,
// in order, from the paragraph that opens with the first effect.
std::vector<std::string> ContractsVocabulary() {
  const std::string text =
      testing::ReadFile(std::filesystem::path(PVTWIN_SOURCE_DIR) / "doc" / "contracts.md");
  const std::string opening = "\n`" + std::string(kEffectNames.front()) + "`, ";
  std::size_t at = text.find(opening);
  if (at == std::string::npos) return {};
  const std::size_t end = text.find(".\n", at);
  std::vector<std::string> names;
  while (true) {
    const std::size_t open = text.find('`', at);
    if (open == std::string::npos || open > end) break;
    const std::size_t close = text.find('`', open + 1);
    names.push_back(text.substr(open + 1, close - open - 1));
    at = close + 1;
  }
  return names;
}

// The registry is the list of effects (core/common/effect_list.h): one
// module per name, in its order, each named as there and owning exactly
// the parameter slots param_list.inc assigns to it.
TEST(EffectRegistry, IsTheListOfEffects) {
  const auto& registry = EffectRegistry();
  ASSERT_EQ(registry.size(), kNumEffects);
  for (std::size_t i = 0; i < registry.size(); ++i) {
    const Effect e = static_cast<Effect>(i);
    EXPECT_EQ(registry[i]->name, EffectName(e));
    EXPECT_EQ(FindEffect(EffectName(e)), registry[i]);
    EXPECT_EQ(registry[i]->params, EffectParams(e)) << registry[i]->name;
    EXPECT_FALSE(registry[i]->params.empty()) << registry[i]->name;
    for (Param p : registry[i]->params) {
      EXPECT_EQ(EffectOfParam(p), e) << registry[i]->name << " " << Info(p).name;
    }
  }
  EXPECT_EQ(FindEffect("none"), nullptr);
  EXPECT_EQ(FindEffect("unknown"), nullptr);
}

// Every parameter slot is the base model's or one module's, never two.
TEST(EffectRegistry, EverySlotHasOneOwner) {
  std::vector<int> owners(kNumParams, 0);
  for (const EffectModule* m : EffectRegistry()) {
    for (Param p : m->params) ++owners[static_cast<std::size_t>(p)];
  }
  for (std::size_t i = 0; i < kNumParams; ++i) {
    const Param p = static_cast<Param>(i);
    EXPECT_EQ(owners[i], EffectOfParam(p).has_value() ? 1 : 0) << Info(p).name;
  }
  // The base model keeps its own (the paper's A_PVT, η_PVref, U_front …).
  EXPECT_FALSE(EffectOfParam(Param::kAreaM2).has_value());
  EXPECT_FALSE(EffectOfParam(Param::kUFrontWM2K).has_value());
}

// doc/contracts.md's vocabulary paragraph names the list's effects, in its
// order.
TEST(EffectRegistry, ContractsVocabularyIsTheList) {
  const std::vector<std::string> documented = ContractsVocabulary();
  ASSERT_EQ(documented.size(), kNumEffects) << "doc/contracts.md's vocabulary paragraph";
  for (std::size_t i = 0; i < kNumEffects; ++i) EXPECT_EQ(documented[i], kEffectNames[i]);
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
