// DemModel checkpoints: every member that carries state from one step to the
// next. Scratch (force buffers, drift velocities, the implicit scheme's
// contact candidates and Newton work arrays, all rebuilt each step) is not saved.
#include "mrf/scene/dem_model.hpp"

namespace mrf {

void save_dem_state(ArchiveWriter& out, const ShearCell& cell, const DemPairLists& lists) {
  out.put(cell.free.x);
  out.put(cell.free.v);
  out.put(cell.free.f);
  out.put(cell.walls.x);
  out.put(lists.ff.start);
  out.put(lists.ff.k);
  out.put(lists.fw);
  out.put(lists.x_ref);
  out.put(lists.x_ref_fw);
  out.put(static_cast<std::uint64_t>(lists.walls_ref));
  out.put(lists.wall_travel);
  out.put(lists.builds);
}

void load_dem_state(ArchiveReader& in, ShearCell& cell, DemPairLists& lists) {
  const std::size_t n_free = cell.free.size(), n_wall = cell.walls.size();
  in.get(cell.free.x);
  in.get(cell.free.v);
  in.get(cell.free.f);
  in.get(cell.walls.x);
  if (cell.free.x.size() != n_free || cell.free.v.size() != n_free || cell.free.f.size() != n_free ||
      cell.walls.x.size() != n_wall)
    throw NumericalError("checkpoint does not match the scene: particle counts differ");
  in.get(lists.ff.start);
  in.get(lists.ff.k);
  in.get(lists.fw);
  in.get(lists.x_ref);
  in.get(lists.x_ref_fw);
  std::uint64_t walls_ref = 0;
  in.get(walls_ref);
  lists.walls_ref = walls_ref;
  in.get(lists.wall_travel);
  in.get(lists.builds);
}

void DemModel::save(ArchiveWriter& out) const {
  save_dem_state(out, cell_, lists_);
  out.put(sums_);
  out.put(time_);
  out.put(steps_);
  if (implicit_) implicit_->save(out);  // the step just taken, the next try, the work so far, the history
}

void DemModel::load(ArchiveReader& in) {
  load_dem_state(in, cell_, lists_);
  in.get(sums_);
  in.get(time_);
  in.get(steps_);
  if (implicit_) implicit_->load(in);
}

}  // namespace mrf
