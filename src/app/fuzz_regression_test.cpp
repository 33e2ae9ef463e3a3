// Replays every input under data/regressions/<target>/ through the same entry point as
// the fuzz target that found it (fuzz/fuzz_entry.h). Each input once crashed, hung,
// leaked or failed unclearly; now it must load or fail with an lc::Error. Under
// `make test-sanitize` ASan/UBSan check the replay too.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "../../fuzz/fuzz_entry.h"
#include "test_util.h"

namespace fs = std::filesystem;

namespace {

std::vector<std::string> inputsOf(const std::string& target) {
  std::vector<std::string> files;
  fs::path dir = lc::testing::dataPath("regressions/" + target);
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.is_regular_file() && e.path().filename().string() != "README.md") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

template <class Fn>
void replay(const std::string& target, Fn&& entry) {
  for (const std::string& f : inputsOf(target)) {
    SCOPED_TRACE(f);
    std::string bytes = slurp(f);
    const auto* data = reinterpret_cast<const uint8_t*>(bytes.data());
    try {
      entry(data, bytes.size());
    } catch (const lc::Error& e) {
      // A clear error is a fine outcome; it must say something.
      EXPECT_FALSE(std::string(e.what()).empty());
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not an lc::Error: " << typeid(e).name() << ": " << e.what();
    }
  }
}

const std::string kSceneDir = lc::testing::dataPath("public-scenes");

TEST(FuzzRegression, RayParser) {
  replay("ray_parser", [](const uint8_t* d, size_t n) { lc::fuzz::parseRay(d, n, kSceneDir); });
}

TEST(FuzzRegression, ObjLoader) {
  replay("obj_loader", [](const uint8_t* d, size_t n) { lc::fuzz::loadObj(d, n); });
}

TEST(FuzzRegression, Image) {
  replay("image", [](const uint8_t* d, size_t n) { lc::fuzz::readImage(d, n); });
}

TEST(FuzzRegression, Scene) {
  replay("scene", [](const uint8_t* d, size_t n) { lc::fuzz::loadScene(d, n, kSceneDir); });
}

// The committed seeds load too (a sanity check that the entry points work at all).
TEST(FuzzRegression, SeedsLoad) {
  for (const auto& e : fs::directory_iterator(lc::testing::sourceDir() + "/fuzz/seeds/image")) {
    SCOPED_TRACE(e.path().string());
    std::string bytes = slurp(e.path().string());
    EXPECT_NO_THROW(lc::fuzz::readImage(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()))
        << "seed image does not decode";
  }
}

}  // namespace
