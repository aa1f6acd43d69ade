// DemModel checkpoints: every member that carries state from one step to the
// next. Scratch (force buffers, drift velocities, the implicit scheme's
// contact candidates and Newton work arrays, all rebuilt each step) is not saved.
#include "mrf/scene/dem_model.hpp"

namespace mrf {

void DemModel::save(ArchiveWriter& out) const {
  out.put(cell_.free.x);
  out.put(cell_.free.v);
  out.put(cell_.free.f);
  out.put(cell_.walls.x);
  out.put(lists_.ff.start);
  out.put(lists_.ff.k);
  out.put(lists_.fw);
  out.put(lists_.x_ref);
  out.put(lists_.x_ref_fw);
  out.put(static_cast<std::uint64_t>(lists_.walls_ref));
  out.put(lists_.wall_travel);
  out.put(lists_.builds);
  out.put(sums_);
  out.put(time_);
  out.put(steps_);
  out.put(dt_);  // implicit scheme: the step just taken, the next try and the work so far
  out.put(dt_try_);
  out.put(counters_);
}

void DemModel::load(ArchiveReader& in) {
  const std::size_t n_free = cell_.free.size(), n_wall = cell_.walls.size();
  in.get(cell_.free.x);
  in.get(cell_.free.v);
  in.get(cell_.free.f);
  in.get(cell_.walls.x);
  if (cell_.free.x.size() != n_free || cell_.free.v.size() != n_free || cell_.free.f.size() != n_free ||
      cell_.walls.x.size() != n_wall)
    throw NumericalError("checkpoint does not match the scene: particle counts differ");
  in.get(lists_.ff.start);
  in.get(lists_.ff.k);
  in.get(lists_.fw);
  in.get(lists_.x_ref);
  in.get(lists_.x_ref_fw);
  std::uint64_t walls_ref = 0;
  in.get(walls_ref);
  lists_.walls_ref = walls_ref;
  in.get(lists_.wall_travel);
  in.get(lists_.builds);
  in.get(sums_);
  in.get(time_);
  in.get(steps_);
  in.get(dt_);
  in.get(dt_try_);
  in.get(counters_);
}

}  // namespace mrf
