#include "mrf/io/atomic_file.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include <fcntl.h>
#include <unistd.h>

#include "mrf/error.hpp"

namespace mrf {

namespace {
// Flushes a file's (or a folder's) contents to the disk: without it a crash
// soon after the rename can leave the new name on an empty file, which a
// sweep would read as a damaged record.
void sync_path(const std::string& path, int flags) {
  const int fd = ::open(path.c_str(), flags);
  if (fd < 0) return;  // a folder that cannot be opened (some file systems): nothing more to do
  ::fsync(fd);
  ::close(fd);
}
}  // namespace

void write_file_atomic(const std::string& path, const std::string& text) {
  // The text goes to path.tmp, which replaces path by a rename only when it
  // was written whole and closed without error (a full disk or a quota can
  // show only at the close): a full disk or a kill leaves the old file (and
  // no partial temporary) behind. The temporary is synced before the
  // rename, the folder after it.
  // the temporary is the process's own: two processes (MPI ranks, job-array
  // tasks) rewriting sweep.csv at once must not write into one temporary
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  errno = 0;
  {
    std::ofstream out(tmp, std::ios::trunc | std::ios::binary);
    if (!out) throw OutputError("cannot write " + tmp + ": " + std::strerror(errno));
    out << text;
    out.close();
    if (out.fail()) {
      const int e = errno;
      std::error_code ignore;
      std::filesystem::remove(tmp, ignore);
      throw OutputError("write failed: " + tmp + ": " + std::strerror(e) + " (" + std::to_string(text.size()) +
                        " bytes to write); " + path + " is left as it was");
    }
  }
  sync_path(tmp, O_RDONLY);
  std::filesystem::rename(tmp, path);
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  sync_path(parent.empty() ? std::string(".") : parent.string(), O_RDONLY | O_DIRECTORY);
}

}  // namespace mrf
