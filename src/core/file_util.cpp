#include "core/file_util.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"

namespace fs = std::filesystem;

namespace lc {

std::string readFile(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw Error("cannot read " + quoteInput(path) + ": it is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot open " + quoteInput(path) + ": " + std::strerror(errno));
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw Error("cannot read " + quoteInput(path) + "");
  return ss.str();
}

static std::string tempNameFor(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  return path + ".tmp-" + std::to_string(getpid()) + "-" + std::to_string(counter++);
}

void writeFileAtomically(const std::string& path,
                         const std::function<void(const std::string&)>& write) {
  std::string tmp = tempNameFor(path);
  try {
    write(tmp);
    // Flush to disk before the rename so a crash cannot leave an empty file behind.
    int fd = ::open(tmp.c_str(), O_RDONLY);
    if (fd < 0) throw Error("cannot write " + quoteInput(path) + ": " + std::strerror(errno));
    int syncErr = ::fsync(fd) == 0 ? 0 : errno;
    ::close(fd);
    if (syncErr != 0 && syncErr != EINVAL)
      throw Error("cannot write " + quoteInput(path) + ": " + std::strerror(syncErr));
    if (std::rename(tmp.c_str(), path.c_str()) != 0)
      throw Error("cannot write " + quoteInput(path) + ": " + std::strerror(errno));
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
}

namespace {
std::string canonicalOrAbsolute(const std::string& p) {
  std::error_code ec;
  // Absolute first: for a path none of whose parts exist yet, weakly_canonical returns it
  // as given ("out.png" vs "./out.png"); lexically_normal removes what is left of "." parts.
  fs::path abs = fs::absolute(fs::path(p), ec);
  if (ec) abs = fs::path(p);
  fs::path c = fs::weakly_canonical(abs, ec);
  if (ec) c = abs;
  return c.lexically_normal().string();
}
}  // namespace

void checkDistinctPaths(const std::vector<NamedPath>& paths) {
  std::vector<std::string> canon(paths.size());
  for (size_t i = 0; i < paths.size(); ++i)
    if (!paths[i].path.empty()) canon[i] = canonicalOrAbsolute(paths[i].path);
  for (size_t j = 0; j < paths.size(); ++j)
    for (size_t i = 0; i < j; ++i) {
      if (paths[i].path.empty() || paths[j].path.empty() || canon[i] != canon[j]) continue;
      const NamedPath &a = paths[i], &b = paths[j];
      if (a.path == b.path)
        throw Error(quoteInput(a.path) + " is given as both " + a.role + " and " + b.role + "; use different files");
      throw Error(quoteInput(b.path) + " (" + b.role + ") is the same file as " + quoteInput(a.path) + " (" + a.role +
                  "); use different files");
    }
}

void checkWritable(const std::string& path) {
  if (path.empty()) throw Error("empty output path");
  std::error_code ec;
  if (fs::is_directory(path, ec))
    throw Error("cannot write " + quoteInput(path) + ": it is a directory");
  std::string tmp = tempNameFor(path);
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
  if (fd < 0) throw Error("cannot write " + quoteInput(path) + ": " + std::strerror(errno));
  ::close(fd);
  ::unlink(tmp.c_str());
}

std::string fileExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  if (!ext.empty() && ext[0] == '.') ext = ext.substr(1);
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

std::string parentDir(const std::string& path) { return fs::path(path).parent_path().string(); }

std::string resolveRelative(const std::string& baseDir, const std::string& path) {
  if (path.empty() || fs::path(path).is_absolute() || baseDir.empty()) return path;
  return (fs::path(baseDir) / path).lexically_normal().string();
}

}  // namespace lc
