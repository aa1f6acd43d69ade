// The one interface the run loop drives (scene/run.cpp): the DEM model of
// model 1 and the coupled DEM-SPH models of models 2 and 3 implement it.
// A model owns its state and forces; its integrator owns its history. The
// loop samples each step, writes rows, checkpoints and the summary, and knows
// nothing of the physics inside.
#pragma once
#include <string>

#include "mrf/io/archive.hpp"
#include "mrf/neighbors/verlet_list.hpp"
#include "mrf/scene/dem_forces.hpp"
#include "mrf/scene/shear_cell.hpp"

namespace mrf {

struct RunSummary;

// What one step contributes to the stress series.
struct StepSample {
  const PairSums& dem;  // particle pair sums of the step (wall forces, virials, overlap, energies)
  double fluid_stress;  // wall shear stress of the fluid (Pa; eta gdot for an imposed profile)
  double fluid_virial;  // volume side of the fluid stress (Pa)
  double weight;        // 1 for fixed steps, the step length (s) for error-controlled ones
};

class Model {
 public:
  virtual ~Model() = default;
  virtual void step() = 0;
  virtual double time() const = 0;   // s
  virtual double dt() const = 0;     // the step just taken (s)
  virtual long steps() const = 0;
  // Error-controlled steps: the loop writes rows by time interval, and the
  // step that would pass the stop time (s) ends on it.
  virtual bool adaptive() const = 0;
  virtual void set_stop_time(double t) = 0;
  virtual StepSample sample() const = 0;
  virtual const ShearCell& cell() const = 0;
  virtual const DemPairLists& lists() const = 0;
  // Checkpoint: the whole state carried from one step to the next.
  virtual void save(ArchiveWriter& out) const = 0;
  virtual void load(ArchiveReader& in) = 0;
  // The model's own fields of summary.json, at the end of a run.
  virtual void finish(RunSummary& s) const = 0;
  // Extra text for the progress line (may be empty).
  virtual std::string progress() const { return {}; }
};

}  // namespace mrf
