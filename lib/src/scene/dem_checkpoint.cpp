// DemModel checkpoints: every member that carries state from one step to the
// next (DemModel::serialize). Scratch (force buffers, drift velocities, the
// implicit scheme's contact candidates and Newton work arrays, all rebuilt
// each step) is not saved.
#include "mrf/error.hpp"
#include "mrf/scene/dem_model.hpp"

namespace mrf {

void check_dem_state(const ShearCell& cell, std::size_t n_free, std::size_t n_wall) {
  const auto& f = cell.free;
  if (f.x.size() != n_free || f.v.size() != n_free || f.f.size() != n_free || cell.walls.x.size() != n_wall)
    throw CheckpointError("checkpoint does not match the scene: particle counts differ");
}

void DemModel::load(ArchiveReader& in) {
  const std::size_t n_free = cell_.free.size(), n_wall = cell_.walls.size();
  serialize(in, *this);
  check_dem_state(cell_, n_free, n_wall);
}

}  // namespace mrf
