// No function of core/ runs over 150 lines (issue 10): a long one is split
// where a reader would name the parts. Counts each definition that starts at
// the first column (free functions and out-of-class members) from its first
// line to the closing brace at the first column.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace pvtwin {
namespace {

constexpr std::size_t kMaxFunctionLines = 150;

bool StartsDefinition(const std::string& line) {
  if (line.empty() || !(std::isalpha(static_cast<unsigned char>(line[0])) || line[0] == '_')) {
    return false;
  }
  for (const char* skip : {"namespace", "using", "struct", "class", "enum", "template", "extern",
                           "static_assert", "inline constexpr", "constexpr"}) {
    if (line.rfind(skip, 0) == 0) return false;
  }
  return line.find('(') != std::string::npos;
}

TEST(CoreStructure, NoFunctionOver150Lines) {
  const std::filesystem::path core = std::filesystem::path(PVTWIN_SOURCE_DIR) / "core";
  std::size_t checked = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(core)) {
    const std::string ext = entry.path().extension().string();
    if (ext != ".cc" && ext != ".h") continue;
    std::ifstream in(entry.path());
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    for (std::size_t i = 0; i < lines.size(); ++i) {
      if (!StartsDefinition(lines[i])) continue;
      // The signature may span lines; a declaration ends with ';' first.
      std::size_t j = i;
      while (j < lines.size() && lines[j].find('{') == std::string::npos &&
             lines[j].find(';') == std::string::npos) {
        ++j;
      }
      if (j >= lines.size() || lines[j].find('{') == std::string::npos) continue;
      if (lines[j].back() == '}') continue;  // a one-line body
      std::size_t k = j;
      while (k < lines.size() && lines[k] != "}") ++k;
      ++checked;
      EXPECT_LE(k - i + 1, kMaxFunctionLines)
          << entry.path().string() << ":" << i + 1 << ": " << lines[i];
      i = k;
    }
  }
  EXPECT_GT(checked, 300u) << "the scan found too few functions to be checking anything";
}

}  // namespace
}  // namespace pvtwin
