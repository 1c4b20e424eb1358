// The code stays readable in one screen (issues 10 and 51): no function of
// core/, io/, daemon/ or config/ runs over 150 lines — a long one is split
// where a reader would name the parts — and no source file there over 1000
// lines. Counts each definition that starts at the first column (free
// functions and out-of-class members) from its first line to the closing
// brace at the first column.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace pvtwin {
namespace {

constexpr std::size_t kMaxFunctionLines = 150;
constexpr std::size_t kMaxFileLines = 1000;

// The folders of the installed code; tests/ and its harness are not scanned.
const char* const kScannedFolders[] = {"core", "io", "daemon", "config"};

struct SourceFile {
  std::filesystem::path path;  // relative to the source tree, for messages
  std::vector<std::string> lines;
};

// Every .cc and .h file under the scanned folders, read line by line.
std::vector<SourceFile> ScannedSources() {
  const std::filesystem::path root(PVTWIN_SOURCE_DIR);
  std::vector<SourceFile> files;
  for (const char* folder : kScannedFolders) {
    for (const auto& entry : std::filesystem::recursive_directory_iterator(root / folder)) {
      const std::string ext = entry.path().extension().string();
      if (!entry.is_regular_file() || (ext != ".cc" && ext != ".h")) continue;
      SourceFile file;
      file.path = entry.path().lexically_relative(root);
      std::ifstream in(entry.path());
      for (std::string line; std::getline(in, line);) file.lines.push_back(line);
      files.push_back(std::move(file));
    }
  }
  return files;
}

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

TEST(SourceStructure, NoFunctionOver150Lines) {
  std::size_t checked = 0;
  std::vector<std::string> folders_with_functions;
  for (const SourceFile& file : ScannedSources()) {
    const std::vector<std::string>& lines = file.lines;
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
      const std::string folder = file.path.begin()->string();
      if (std::find(folders_with_functions.begin(), folders_with_functions.end(), folder) ==
          folders_with_functions.end()) {
        folders_with_functions.push_back(folder);
      }
      EXPECT_LE(k - i + 1, kMaxFunctionLines)
          << file.path.string() << ":" << i + 1 << ": " << lines[i];
      i = k;
    }
  }
  EXPECT_GT(checked, 1000u) << "the scan found too few functions to be checking anything";
  EXPECT_EQ(folders_with_functions.size(), std::size(kScannedFolders))
      << "a scanned folder holds no function the scan recognises";
}

TEST(SourceStructure, NoFileOver1000Lines) {
  const std::vector<SourceFile> files = ScannedSources();
  EXPECT_GT(files.size(), 200u) << "the scan found too few files to be checking anything";
  for (const SourceFile& file : files) {
    EXPECT_LE(file.lines.size(), kMaxFileLines) << file.path.string();
  }
}

}  // namespace
}  // namespace pvtwin
