#pragma once
// Test support: a temporary folder that removes itself, and a file's text.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>

namespace runout::test_support {

/// The whole text of a file ("" when it cannot be read).
inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// A fresh folder under the system's temporary folder, removed with everything in it at the end.
struct TempDir {
  std::filesystem::path p;
  TempDir() {
    static int n = 0;
    p = std::filesystem::temp_directory_path() / ("runout-test-" + std::to_string(getpid()) + "-" + std::to_string(n++));
    std::filesystem::create_directories(p);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(p, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  /// A path inside the folder.
  std::string operator/(const std::string& name) const { return (p / name).string(); }
};

}  // namespace runout::test_support
