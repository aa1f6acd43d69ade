// CoupledModel checkpoints: every member that carries state from one fluid
// step to the next.
//
// Saved: the DEM part shared with DemModel (free x, v, f: f enters the first
// sub-step's force average; wall sphere positions; the Verlet lists as
// built), the SPH fluid particles' x, v, a_ext and rest densities (set once
// from the start state, carried with the particle), the SPH wall particles'
// x and v, the wall-reflection count, the external impulse and the clock.
//
// Not saved, because they are functions of the saved positions and load()
// recomputes them with the calls that end step(), refresh() and
// update_coupling_pairs(): the SPH pairs, summation densities, porosities,
// fluid and wall pressures and wall densities, the DEM-SPH pairs (with the
// wall mirror images) and the porosity range of sums_. Not saved because
// step() recomputes them before use: the Shepard fields, buoyancy, friction
// coefficients and parcel state (prepare_coupling sets parcel u to the fluid
// velocity and zeroes the impulse every fluid step), f_old_/f_new_ (set in
// each sub-step), the force buffers and the per-step sums. Not state:
// parameters, dt, substeps, drag law, overlap limit and the wall particles'
// depth and side (fixed by the scene), and the body force (set by the caller).
#include "mrf/scene/coupled_model.hpp"

#include "mrf/fluid/wcsph.hpp"
#include "mrf/scene/dem_model.hpp"

namespace mrf {

void CoupledModel::save(ArchiveWriter& out) const {
  save_dem_state(out, cell_, lists_);
  const FluidParticles& f = fluid_.fluid;
  out.put(f.x);
  out.put(f.v);
  out.put(f.a_ext);
  out.put(f.rest_density);
  out.put(fluid_.wall.x);
  out.put(fluid_.wall.v);
  out.put(sums_.wall_reflections);
  out.put(external_impulse_);
  out.put(time_);
  out.put(steps_);
  out.put(eps_seen_min_);
  out.put(eps_seen_max_);
  out.put(clamped_steps_);
  if (implicit_) {
    implicit_->save(out);
    out.put(fluid_substeps_);
  }
}

void CoupledModel::load(ArchiveReader& in) {
  load_dem_state(in, cell_, lists_);
  FluidParticles& f = fluid_.fluid;
  const std::size_t nf = f.size(), nw = fluid_.wall.size();
  in.get(f.x);
  in.get(f.v);
  in.get(f.a_ext);
  in.get(f.rest_density);
  in.get(fluid_.wall.x);
  in.get(fluid_.wall.v);
  if (f.x.size() != nf || f.v.size() != nf || f.a_ext.size() != nf || f.rest_density.size() != nf ||
      fluid_.wall.x.size() != nw || fluid_.wall.v.size() != nw)
    throw NumericalError("checkpoint does not match the scene: SPH particle counts differ");
  in.get(sums_.wall_reflections);
  in.get(external_impulse_);
  in.get(time_);
  in.get(steps_);
  in.get(eps_seen_min_);
  in.get(eps_seen_max_);
  in.get(clamped_steps_);
  if (implicit_) {
    implicit_->load(in);
    in.get(fluid_substeps_);
  }
  fluid_.time = time_;
  fluid_.steps = steps_;
  refresh(fluid_);  // as at the end of step()
  update_coupling_pairs();
}

}  // namespace mrf
