// Pieces of a run loop shared by the DEM and the coupled runs: time-series
// rows (sums over the steps between two rows), the block-averaged stress
// series of the steady part, the timeseries.csv format and particle frames.
#pragma once
#include <ostream>
#include <vector>

#include "mrf/io/archive.hpp"
#include "mrf/scene/dem_forces.hpp"
#include "mrf/scene/run.hpp"
#include "mrf/scene/shear_cell.hpp"

namespace mrf {

// Running sums of one time-series row (stresses in Pa, overlap in m, J).
struct SeriesRow {
  double particles = 0, fluid = 0, vir_mag = 0, vir_con = 0, vir_fluid = 0, max_overlap = 0, e_dip = 0,
         e_hertz = 0;
  double n = 0;  // sum of the step weights
  // One step of weight w (1 for fixed steps, the step length for the adaptive
  // implicit scheme): the particles' pair sums, the fluid's wall stress and
  // the fluid's virial stress (Pa; eta gdot for the imposed profile of model 1).
  void add(const PairSums& p, const Box& box, double fluid_stress, double fluid_virial, double w = 1.0);
};

// Row means after the warm-up, block-averaged at the end (observe/block_average).
class StressSeries {
 public:
  void push(const SeriesRow& row);
  // Fills stress_total, stress_particles, stress_fluid (mean), stress_virial
  // (particle pair virial; the fluid part is stress_fluid in every model),
  // its magnetic and contact parts, and wall_minus_virial (particle wall
  // stress - pair virial). The volume-side total, pair virial + fluid
  // virial, goes to extra["stress_virial_total"] (+ "_err") beside
  // extra["stress_virial_fluid"]: it must match stress_total in steady state.
  void finish(RunSummary& s) const;
  std::size_t size() const { return total_.size(); }
  Measurement fluid() const;
  void save(ArchiveWriter& a) const;  // checkpoints
  void load(ArchiveReader& a);

 private:
  std::vector<double> total_, particles_, fluid_, virial_, mag_, con_, diff_, vir_fluid_, vir_total_;
};

void write_series_header(std::ostream& out);
void write_series_row(std::ostream& out, double time, double strain, const SeriesRow& row, double radius);

// Extended-XYZ frame of free and wall spheres (OVITO, ParaView).
void write_frame(std::ostream& out, const ShearCell& cell, double radius, double time);

// Steps between rows (output.every or ~2000 rows) and the check that at
// least 32 rows follow the warm-up; throws InputError on output.every.
long series_every(const LoadedScene& scene, long steps);

}  // namespace mrf
