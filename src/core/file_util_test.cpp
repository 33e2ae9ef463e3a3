// Reading whole files: readFile and readFileBytes give the file's exact bytes (empty files,
// files past the huge-page threshold, files read from a pipe) and clear errors otherwise.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "core/error.h"
#include "core/file_util.h"
#include "test_util.h"

namespace lc {
namespace {

using lc::testing::TempDir;

void write(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

// Bytes that are not text: every value, and NULs, which a C-string read would stop at.
std::string pattern(size_t n) {
  std::string s(n, '\0');
  for (size_t i = 0; i < n; ++i) s[i] = char((i * 131 + i / 7) & 0xff);
  return s;
}

TEST(ReadFile, GivesTheExactBytesOfSmallEmptyAndLargeFiles) {
  TempDir dir;
  // 9 MB: past HugePageAllocator's 4 MiB threshold, so readFileBytes takes huge pages.
  for (size_t n : {size_t(0), size_t(1), size_t(65537), size_t(9) << 20}) {
    const std::string path = dir.file(std::to_string(n) + ".bin");
    const std::string bytes = pattern(n);
    write(path, bytes);
    EXPECT_EQ(readFile(path), bytes) << n;
    const BigVector<char> b = readFileBytes(path);
    ASSERT_EQ(b.size(), n);
    EXPECT_TRUE(std::string(b.data(), b.size()) == bytes) << n;
  }
}

TEST(ReadFile, ReadsAPipeToItsEnd) {
  // A FIFO has no size to allocate ahead: what it carries is read in blocks until EOF.
  TempDir dir;
  const std::string fifo = dir.file("p");
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const std::string bytes = pattern(200000);
  pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    std::FILE* f = std::fopen(fifo.c_str(), "wb");
    if (f) {
      std::fwrite(bytes.data(), 1, bytes.size(), f);
      std::fclose(f);
    }
    _exit(0);
  }
  const BigVector<char> b = readFileBytes(fifo);
  EXPECT_TRUE(std::string(b.data(), b.size()) == bytes);
}

TEST(ReadFile, MissingFilesAndDirectoriesAreClearErrors) {
  TempDir dir;
  try {
    readFileBytes(dir.file("missing.ray"));
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot open"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("missing.ray"), std::string::npos) << e.what();
  }
  try {
    readFile(dir.path());
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("directory"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace lc
