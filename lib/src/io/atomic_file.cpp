#include "mrf/io/atomic_file.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "mrf/error.hpp"

namespace mrf {

void write_file_atomic(const std::string& path, const std::string& text) {
  // The text goes to path.tmp, which replaces path by a rename only when it
  // was written whole: a full disk or a kill leaves the old file (and no
  // partial temporary) behind.
  // the temporary is the process's own: two processes (MPI ranks, job-array
  // tasks) rewriting sweep.csv at once must not write into one temporary
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  errno = 0;
  {
    std::ofstream out(tmp, std::ios::trunc | std::ios::binary);
    if (!out) throw OutputError("cannot write " + tmp + ": " + std::strerror(errno));
    out << text;
    out.flush();
    if (!out) {
      const int e = errno;
      out.close();
      std::error_code ignore;
      std::filesystem::remove(tmp, ignore);
      throw OutputError("write failed: " + tmp + ": " + std::strerror(e) + " (" + std::to_string(text.size()) +
                        " bytes to write); " + path + " is left as it was");
    }
  }
  std::filesystem::rename(tmp, path);
}

}  // namespace mrf
