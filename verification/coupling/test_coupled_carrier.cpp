// The SPH carrier of the coupled models at rest in a porosity field
// (REFERENCE §6): the averaged continuity equation makes the fluid's
// superficial density eps rho_f, so a carrier at rest, whatever its history,
// has one intrinsic density rho / eps everywhere. A bed of immobile spheres
// fills the lower half of the gap (eps about 0.87 there, 1 above); the fluid
// starts on its lattice, uniform in superficial density, i.e. too dense
// inside the bed and too thin above it.
// - fluid.eos_reference = "common" (rho_f for every particle, the model of
//   REFERENCE §6): the pressure drives fluid out of the bed until the
//   intrinsic densities agree.
// - "start" (each particle's intrinsic density at the start): the start is
//   free of pressure, and the mismatch stays, carried by the particles.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "mrf/io/toml_scene.hpp"
#include "mrf/scene/build_model.hpp"
#include "mrf/scene/coupled_model.hpp"
#include "mrf/scene/dem_params.hpp"
#include "support/coupling_cell.hpp"

namespace mrf {
namespace {

const std::string kSmall = MRF_SOURCE_DIR "/experiments/scenes/small_demsph_stokes.toml";

struct Rest {
  double bed, free;  // mean intrinsic density rho/eps of the SPH particles deep in the bed and above it (kg/m^3)
  double start_bed, start_free;
  double rho_f;  // the fluid density (kg/m^3)
};

Rest carrier_at_rest(bool common, int steps) {
  LoadedScene scene = load_scene(kSmall, {"particles.volume_fraction=0.0", "particles.magnetization=0.0",
                                          "drive.shear_rate=1e-9", "fluid.sound_speed=40.0", "box.gap=160e-6"});
  SceneConfig& c = scene.config;
  DemParams p = dem_params(c);
  p.mass *= 1e9;  // immobile on the time of the test
  // an 8 um lattice, phi = 0.128 in the bed
  ShearCell cell = test::sphere_lattice(Box{c.gap, c.ly, c.lz}, c.ly / 4.0, 10, 4, 4);
  FluidCell fluid = build_coupled_fluid(c, cell);
  fluid.params.common_eos_reference = common;
  for (auto& v : fluid.fluid.v) v.setZero();
  const double dt = 0.5 * 0.25 * fluid.h / fluid.c0;
  CoupledModel m(std::move(cell), p, std::move(fluid), CoupledDrag::stokes, dt, 1);
  auto means = [&](double& bed, double& free) {
    const auto& f = m.fluid().fluid;
    double sb = 0, sf = 0;
    int nb = 0, nf = 0;
    const double h = m.fluid().h;
    for (std::size_t q = 0; q < f.size(); ++q) {
      const double x = f.x[q].x(), intrinsic = f.rho[q] / f.eps[q];
      if (x < -2.0 * h && x > -0.5 * c.gap + 2.0 * h) sb += intrinsic, ++nb;  // 2h inside the bed, 2h off the wall
      if (x > 2.0 * h && x < 0.5 * c.gap - 2.0 * h) sf += intrinsic, ++nf;
    }
    bed = sb / nb;
    free = sf / nf;
  };
  Rest r{};
  r.rho_f = c.fluid_density;
  means(r.start_bed, r.start_free);
  for (int n = 0; n < steps; ++n) m.step();
  means(r.bed, r.free);
  return r;
}

// About 4.5 relaxation times (the bed's mismatch falls about e-fold per
// 560 steps): the two regions agree within 0.3 % where they started 14 %
// apart, at rho_f within 0.4 % (the lattice's mass is (1 - phi) rho_f per
// volume and the mean porosity is 1 - phi). A wrong sign of the pressure
// force or of the EOS would drive them apart instead.
TEST(CoupledCarrier, CommonReferenceRelaxesToOneIntrinsicDensity) {
  const Rest r = carrier_at_rest(true, 2500);
  const double rho_f = r.rho_f;
  EXPECT_GT(r.start_bed / r.start_free - 1.0, 0.10);
  EXPECT_LT(std::abs(r.bed / r.free - 1.0), 0.003) << r.bed << " " << r.free;
  EXPECT_NEAR(r.bed, rho_f, 0.004 * rho_f);
  EXPECT_NEAR(r.free, rho_f, 0.004 * rho_f);
  RecordProperty("bed_over_free", std::to_string(r.bed / r.free));
}

// Each particle's own reference: the start is free of pressure and nothing
// moves, so the fluid in the bed stays 14 % denser than above it.
TEST(CoupledCarrier, StartReferenceKeepsTheStartsMismatch) {
  const Rest r = carrier_at_rest(false, 50);
  EXPECT_GT(r.bed / r.free - 1.0, 0.10);
  EXPECT_DOUBLE_EQ(r.bed, r.start_bed);
}

}  // namespace
}  // namespace mrf
