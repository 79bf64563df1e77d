// Every file the CLI writes (--out-ply, --out-csv, --png, --histogram-png)
// goes through writeOutputFile, so that no reader ever sees a partial file
// under the final name and an earlier good file survives a failed write:
//
//   1. the bytes go to a new temporary file "<name>.XXXXXX.tmp" in the same
//      directory (created exclusively; the name shortened to fit NAME_MAX), made
//      readable as a fresh file would be (0666 & ~umask);
//   2. it is written completely, fsync'd and closed, each step checked;
//   3. it is renamed over the final name (atomic within one file system),
//      then the directory is fsync'd so that the rename is durable.
//
// On any failure the temporary file is removed. A SIGINT, SIGTERM or SIGHUP
// that arrives while a temporary file exists removes it before the process
// dies with that signal (SIGKILL cannot be caught: it may leave one *.tmp).
//
// An existing path that is a symbolic link is followed: the file it points
// to is replaced, the link kept. An existing path that is not a regular file
// (/dev/null, /dev/full, a FIFO) is written in place: it cannot be renamed
// over, and replacing a device node with a regular file would be wrong.
#pragma once

#include <string>
#include <string_view>

#include "rthdist/result.hpp"

namespace rthdist::cli {

// Writes `bytes` to `path` as above. The error's message names the file and
// the system's reason (strerror), e.g. "cannot write output 'x.csv': No space
// left on device"; the CLI exits kExitOutput with it.
[[nodiscard]] Result<bool> writeOutputFile(const std::string& path, std::string_view bytes);

}  // namespace rthdist::cli
