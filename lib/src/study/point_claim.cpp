#include "mrf/study/point_claim.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>

#include "mrf/error.hpp"

namespace mrf {
namespace {

std::string read_all(int fd) {
  std::string text;
  char buf[256];
  off_t at = 0;
  for (ssize_t n; (n = pread(fd, buf, sizeof buf, at)) > 0; at += n) text.append(buf, static_cast<std::size_t>(n));
  while (!text.empty() && (text.back() == '\n' || text.back() == '\0')) text.pop_back();
  return text.empty() ? "another process" : text;
}

std::string whoami() {
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  char when[32] = {};
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  std::strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return "pid " + std::to_string(getpid()) + " on host " + host + " since " + when + "\n";
}

}  // namespace

std::filesystem::path point_claim_path(const std::filesystem::path& point_dir) {
  return std::filesystem::path(point_dir.string() + ".claim");
}

PointClaim::PointClaim(const std::filesystem::path& point_dir) {
  const std::filesystem::path file = point_claim_path(point_dir);
  std::error_code ec;
  std::filesystem::create_directories(file.parent_path(), ec);
  const std::string path = file.string();
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) throw OutputError("cannot open the point's claim " + path + ": " + std::strerror(errno));
  // A few tries before giving up: `--list` probes with a shared lock and a
  // sweep sets a stale folder aside under a claim, each for a moment; a
  // point that is being run is held for its whole run.
  int e = 0;
  for (int attempt = 0; attempt < 10; ++attempt) {
    e = ::flock(fd, LOCK_EX | LOCK_NB) == 0 ? 0 : errno;
    if (e != EWOULDBLOCK) break;
    ::usleep(20000);
  }
  if (e != 0) {
    holder_ = read_all(fd);
    ::close(fd);
    if (e != EWOULDBLOCK) throw OutputError("cannot lock the point's claim " + path + ": " + std::strerror(e));
    return;
  }
  const std::string me = whoami();
  if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, me.data(), me.size(), 0) != static_cast<ssize_t>(me.size())) {
    const int w = errno;
    ::close(fd);
    throw OutputError("cannot write the point's claim " + path + ": " + std::strerror(w));
  }
  fd_ = fd;
}

PointClaim::~PointClaim() {
  if (fd_ >= 0) ::close(fd_);  // drops the lock
}

std::string point_claim_holder(const std::filesystem::path& point_dir) {
  const std::string path = point_claim_path(point_dir).string();
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return "";
  std::string who;
  if (::flock(fd, LOCK_SH | LOCK_NB) != 0) who = read_all(fd);  // an exclusive lock is held
  ::close(fd);
  return who;
}

}  // namespace mrf
