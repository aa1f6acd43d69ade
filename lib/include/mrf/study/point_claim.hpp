// Which process runs a sweep point now, so that several `mrf sweep`
// processes can work through one sweep output side by side (one per core,
// without MPI and without handing out `--point` lists by hand): a process
// runs a point only while it holds the point's claim, and passes over a
// point another live process holds.
//
// The claim is an exclusive flock(2) on <point folder>.claim (beside the
// folder, not in it: a sweep that sets a run of another scene aside renames
// the folder, and does so only under the claim, so a running point's folder
// is never moved from under it), taken without blocking (a few tries over
// 0.2 s, for probes that hold it a moment) and held for as long as the
// PointClaim lives. The kernel drops it
// when its process ends however it ends (exit, SIGKILL, a crash), so a claim
// is never left stale; a stopped process (SIGSTOP) still holds it. The file
// stays (removing it while another process may have it open would let two
// processes lock two different files); it says who holds or held it, for
// messages and `mrf sweep --list`.
#pragma once
#include <filesystem>
#include <string>

namespace mrf {

class PointClaim {
 public:
  // Creates the folder the point's folder is in, if need be, and tries to
  // take the point's claim.
  explicit PointClaim(const std::filesystem::path& point_dir);
  ~PointClaim();
  PointClaim(const PointClaim&) = delete;
  PointClaim& operator=(const PointClaim&) = delete;

  bool owned() const { return fd_ >= 0; }
  // When not owned: who holds it ("pid 1234 on host h since 2026-12-06T20:40:00Z",
  // as the holder wrote it; "another process" if it has not written it yet).
  const std::string& holder() const { return holder_; }

 private:
  int fd_ = -1;
  std::string holder_;
};

// Whether a live process holds the point's claim now, and who ("" if none);
// takes nothing and creates nothing (for `--list`).
std::string point_claim_holder(const std::filesystem::path& point_dir);
// The claim's file: <point folder>.claim.
std::filesystem::path point_claim_path(const std::filesystem::path& point_dir);

}  // namespace mrf
