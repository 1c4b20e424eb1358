// The keys a reload changed (config/config_diff.h), as the daemon logs them.
#include "config/config_diff.h"

#include <gtest/gtest.h>

namespace pvtwin {
namespace {

std::vector<std::string> Lines(const std::vector<ConfigChange>& changes) {
  std::vector<std::string> lines;
  for (const ConfigChange& c : changes) {
    lines.push_back(c.Name() + " " + c.old_value + " -> " + c.new_value);
  }
  return lines;
}

TEST(ConfigDiff, NamesEachChangedAddedAndRemovedKeyWithItsValuesAsWritten) {
  const std::string before =
      "[plant]\narea_m2 = 1.8\ntilt_deg = 20\n\n[forecast]\nrefresh_min = 60\n"
      "[storage]\npath = \"/var/lib/pvtwin/a.db\"\n"
      "[[modbus.device]]\nname = \"collector\"\nhost = \"10.0.0.2\"\n"
      "[[modbus.device]]\nname = \"weather\"\nhost = \"10.0.0.3\"\n";
  // Same values reordered and re-spaced, one changed, one removed, one added,
  // the second device moved to another host, a third device.
  const std::string after =
      "[forecast]\nrefresh_min   = 30  # faster\n[plant]\ntilt_deg = 20\narea_m2 = 1.8\n"
      "[log]\nstatus_min = 5\n"
      "[[modbus.device]]\nname = \"collector\"\nhost = \"10.0.0.2\"\n"
      "[[modbus.device]]\nname = \"weather\"\nhost = \"10.0.0.9\"\n"
      "[[modbus.device]]\nname = \"meter\"\nhost = \"10.0.0.4\"\n";
  std::vector<ConfigChange> changes;
  std::string error;
  ASSERT_TRUE(DiffConfigTexts(before, after, &changes, &error)) << error;
  const std::vector<std::string> expected = {
      "[forecast] refresh_min 60 -> 30",
      "[log] status_min (not set) -> 5",
      "[[modbus.device]] #2 host \"10.0.0.3\" -> \"10.0.0.9\"",
      "[[modbus.device]] #3 host (not set) -> \"10.0.0.4\"",
      "[[modbus.device]] #3 name (not set) -> \"meter\"",
      "[storage] path \"/var/lib/pvtwin/a.db\" -> (not set)",
  };
  EXPECT_EQ(Lines(changes), expected);
  EXPECT_EQ(changes[1].section, "log");
  EXPECT_EQ(changes[2].section, "modbus.device");
  EXPECT_EQ(changes[2].entry, 2);

  ASSERT_TRUE(DiffConfigTexts(before, before, &changes, &error));
  EXPECT_TRUE(changes.empty());
  EXPECT_FALSE(DiffConfigTexts(before, "[plant\n", &changes, &error));
  EXPECT_FALSE(error.empty());
}

}  // namespace
}  // namespace pvtwin
