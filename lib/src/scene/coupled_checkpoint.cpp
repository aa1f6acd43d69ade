// CoupledModel checkpoints: every member that carries state from one fluid
// step to the next.
//
// Saved: the DEM part shared with DemModel (free x, v, f: f enters the first
// sub-step's force average; wall sphere positions; the Verlet lists as
// built), the SPH fluid particles' x, v, a_ext and rest densities (set once
// from the start state, carried with the particle), the SPH wall particles'
// x and v, the wall-reflection count, the external impulse, the clock and the
// run-long porosity records; inertialess, the implicit scheme's history
// (integrate/implicit_stepper.hpp) and the work counters. The field list is
// CoupledModel::serialize (coupled_model.hpp), one for both directions.
//
// Not saved, because they are functions of the saved positions and load()
// recomputes them with the calls that end step(), refresh() and
// update_coupling_pairs(): the SPH pairs, summation densities, porosities,
// fluid and wall pressures and wall densities, the DEM-SPH pairs (with the
// wall mirror images), the SPH pair cache's candidates (found again from
// its saved reference positions: the same sorted list; the inertial scheme
// saves none and builds its cache anew, the same pairs) and the porosity
// range of sums_. The coupling pair cache is saved by its reference
// positions, wall-mirrored particles, build time and count, and its
// candidates found again from the reference positions (the same sorted
// list; the pairs would be the same without it, but not the rebuilds).
// Not saved because
// step() recomputes them before use: the Shepard fields, buoyancy, friction
// coefficients and parcel state (prepare_coupling sets parcel u to the fluid
// velocity and zeroes the impulse every fluid step), f_old_/f_new_ (set in
// each sub-step), the fluid response and drift of the inertialess step, the
// force buffers and the per-step sums. Not state:
// parameters, dt, substeps, drag law, overlap limit and the wall particles'
// depth and side (fixed by the scene), and the body force (set by the caller).
#include "mrf/scene/coupled_model.hpp"

#include "mrf/error.hpp"
#include "mrf/fluid/kernel.hpp"
#include "mrf/fluid/wcsph.hpp"
#include "mrf/scene/dem_model.hpp"

namespace mrf {

void CoupledModel::load(ArchiveReader& in) {
  const std::size_t n_free = cell_.free.size(), n_wall = cell_.walls.size();
  const FluidParticles& f = fluid_.fluid;
  const std::size_t nf = f.size(), nw = fluid_.wall.size();
  serialize(in, *this);
  check_dem_state(cell_, n_free, n_wall);
  if (f.x.size() != nf || f.v.size() != nf || f.a_ext.size() != nf || f.rest_density.size() != nf ||
      fluid_.wall.x.size() != nw || fluid_.wall.v.size() != nw)
    throw CheckpointError("checkpoint does not match the scene: SPH particle counts differ");
  fluid_.time = time_;
  fluid_.steps = steps_;
  // as at the end of step(); the SPH pair cache finds its candidates again
  // at its reference positions (the inertial scheme does not save them: its
  // cache is built anew, and the pairs are the same sorted list)
  if (!implicit_) sph_pairs_.x_fluid.clear();
  restore_candidates(fluid_, sph_pairs_);
  refresh(fluid_, sph_pairs_);
  if (!coupling_cache_.dem_ref.empty())
    coupling_candidates(coupling_cache_.dem_ref, coupling_cache_.sph_ref, cell_.box,
                        k_kernel_support * fluid_.h + coupling_cache_.skin, coupling_cache_.candidates);
  update_coupling_pairs();
}

}  // namespace mrf
