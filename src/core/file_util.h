// File helpers: reading whole files, atomic writes and early writability checks.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "core/huge_pages.h"

namespace lc {

// Reads a whole file; throws lc::Error naming the path when it cannot.
std::string readFile(const std::string& path);
// The same, into huge pages and without zero-filling them first: for scene files of
// hundreds of megabytes, whose reading into a string was mostly page faults (a 388 MB scene
// of 2M point lights: 5.2 s through a string stream, 1.6 s into a sized string, 0.3 s here).
BigVector<char> readFileBytes(const std::string& path);

// Writes `path` atomically: `write` fills a temporary file in the same directory,
// which is then renamed over `path`. On any failure the temporary is removed, the old
// file (if any) is untouched, and lc::Error is thrown. A symlink is followed: its target
// is replaced, the link kept. A character device or FIFO (/dev/null, /dev/stdout) is
// written directly (`write` gets `path` itself), never replaced. Any other existing
// non-regular file, and a read-only file (no write permission bits, or not writable by
// this user), is refused: "cannot write 'p': it is read-only".
void writeFileAtomically(const std::string& path,
                         const std::function<void(const std::string& tmpPath)>& write);

// Throws lc::Error when a file could not be created at `path` (missing or unwritable
// directory) or writeFileAtomically would refuse it (read-only, not a regular file), so a
// long render fails before it starts rather than after.
void checkWritable(const std::string& path);

// A file the command reads or writes, with what it is ("the output image (-o)").
struct NamedPath {
  std::string path;  // "" = not given (skipped)
  std::string role;
};
// Throws lc::Error when two of `paths` name the same file (compared with
// std::filesystem::weakly_canonical, so "o.png", "./o.png" and a symlink to it collide):
// an output must not overwrite an input or another output of the same command.
void checkDistinctPaths(const std::vector<NamedPath>& paths);

// Lower-case extension without the dot ("png"), or "" when there is none.
std::string fileExtension(const std::string& path);

// Directory part of a path ("" for a bare file name) and joining of relative paths.
std::string parentDir(const std::string& path);
std::string resolveRelative(const std::string& baseDir, const std::string& path);

}  // namespace lc
