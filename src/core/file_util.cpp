#include "core/file_util.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>

#include "core/error.h"

namespace fs = std::filesystem;

namespace lc {

namespace {

// The whole file at `path` in a Buffer (std::string or BigVector<char>): one allocation of
// the file's size, read into directly (through a string stream the buffer was grown and
// copied by doubling, then copied out); a file that grows meanwhile is read to its end.
template <class Buffer>
Buffer readWhole(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw Error("cannot read " + quoteInput(path) + ": it is a directory");
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"), &std::fclose);
  std::FILE* f = file.get();
  if (!f) throw Error("cannot open " + quoteInput(path) + ": " + std::strerror(errno));
  struct stat st {};
  Buffer text;
  if (fstat(fileno(f), &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0) text.resize(size_t(st.st_size));
  text.resize(std::fread(text.data(), 1, text.size(), f));
  char buf[1 << 16];
  for (size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) text.insert(text.end(), buf, buf + n);
  if (std::ferror(f)) throw Error("cannot read " + quoteInput(path));
  return text;
}

}  // namespace

std::string readFile(const std::string& path) { return readWhole<std::string>(path); }

BigVector<char> readFileBytes(const std::string& path) { return readWhole<BigVector<char>>(path); }

static std::string tempNameFor(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  return path + ".tmp-" + std::to_string(getpid()) + "-" + std::to_string(counter++);
}

namespace {

// Where an output to `path` goes. A symlink is followed to the file it names (the link
// stays a link); a character device, FIFO or socket (/dev/null, /dev/stdout) is written in place,
// since renaming over it would replace the node; anything else that exists must be a
// writable regular file.
struct OutputTarget {
  std::string path;     // the file to replace (or write directly)
  bool direct = false;  // a device, FIFO or socket: write to it, no temporary, no rename
};

OutputTarget outputTarget(const std::string& path) {
  OutputTarget t{path, false};
  // Checked through any links first: /dev/stdout links to /proc/self/fd/1, whose own link
  // text ("pipe:[123]") is no path.
  struct stat st;
  if (::stat(path.c_str(), &st) == 0 && (S_ISCHR(st.st_mode) || S_ISFIFO(st.st_mode) || S_ISSOCK(st.st_mode))) {
    t.direct = true;
    return t;
  }
  fs::path p(path);
  for (int hops = 0;; ++hops) {
    struct stat ls;
    if (::lstat(p.c_str(), &ls) != 0 || !S_ISLNK(ls.st_mode)) break;
    if (hops >= 40) throw Error("cannot write " + quoteInput(path) + ": " + std::strerror(ELOOP));
    fs::path link = fs::read_symlink(p);
    p = link.is_absolute() ? link : p.parent_path() / link;
  }
  t.path = p.lexically_normal().string();
  if (::stat(t.path.c_str(), &st) != 0) return t;  // a new file
  if (S_ISDIR(st.st_mode)) throw Error("cannot write " + quoteInput(path) + ": it is a directory");
  if (!S_ISREG(st.st_mode))
    throw Error("cannot write " + quoteInput(path) + ": it is not a regular file, a character device or a FIFO");
  // Root may write anything, so the mode bits decide as well as access().
  if ((st.st_mode & 0222) == 0 || (::access(t.path.c_str(), W_OK) != 0 && (errno == EACCES || errno == EROFS)))
    throw Error("cannot write " + quoteInput(path) + ": it is read-only");
  return t;
}

}  // namespace

void writeFileAtomically(const std::string& path,
                         const std::function<void(const std::string&)>& write) {
  const OutputTarget target = outputTarget(path);
  if (target.direct) {
    write(target.path);
    return;
  }
  std::string tmp = tempNameFor(target.path);
  try {
    write(tmp);
    // Flush to disk before the rename so a crash cannot leave an empty file behind.
    int fd = ::open(tmp.c_str(), O_RDONLY);
    if (fd < 0) throw Error("cannot write " + quoteInput(path) + ": " + std::strerror(errno));
    int syncErr = ::fsync(fd) == 0 ? 0 : errno;
    ::close(fd);
    if (syncErr != 0 && syncErr != EINVAL)
      throw Error("cannot write " + quoteInput(path) + ": " + std::strerror(syncErr));
    if (std::rename(tmp.c_str(), target.path.c_str()) != 0)
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
  const OutputTarget target = outputTarget(path);
  if (target.direct) {
    int fd = ::open(target.path.c_str(), O_WRONLY | O_NONBLOCK);
    // A FIFO with no reader yet (ENXIO) is fine: the write opens it later and waits.
    if (fd < 0 && errno != ENXIO) throw Error("cannot write " + quoteInput(path) + ": " + std::strerror(errno));
    if (fd >= 0) ::close(fd);
    return;
  }
  std::string tmp = tempNameFor(target.path);
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
