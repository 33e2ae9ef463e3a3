// Helpers shared by the test binaries: fixture paths, temporary directories, the CLI binary.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace lc::testing {

// The repository root (fixtures live under data/ and scenes/).
inline std::string sourceDir() {
  const char* env = std::getenv("LC_SOURCE_DIR");
  return env ? env : LC_SOURCE_DIR;
}
inline std::string dataPath(const std::string& rel) { return sourceDir() + "/data/" + rel; }
inline std::string scenePath(const std::string& rel) { return sourceDir() + "/scenes/" + rel; }

// The lightcuts binary: $LC_BINARY, or beside the test executable in the build directory.
inline std::string binary() {
  if (const char* b = std::getenv("LC_BINARY")) return b;
  return (std::filesystem::read_symlink("/proc/self/exe").parent_path() / "lightcuts").string();
}

// A whole file's bytes ("" when it cannot be read).
inline std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// A fresh temporary directory per test, removed at destruction.
class TempDir {
 public:
  TempDir() {
    std::string tmpl = (std::filesystem::temp_directory_path() / "lc-test-XXXXXX").string();
    char* p = mkdtemp(tmpl.data());
    path_ = p ? p : tmpl;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  const std::string& path() const { return path_; }
  std::string file(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

}  // namespace lc::testing
