#pragma once
/// Small helpers shared by the test files.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "host/config/config.hpp"
#include "kernels/contact/contact_law.hpp"

namespace dem::test {

constexpr double kPi = 3.14159265358979323846;

/// The triaxdem program the tests that run it as a child use: the build's own, or $TRIAXDEM_BINARY where the tests
/// run away from their build folder (a GPU machine gets the programs alone: perf/device_check.sh pack).
inline std::string triaxdem_binary() {
  const char* moved = std::getenv("TRIAXDEM_BINARY");
  return moved && *moved ? moved : TRIAXDEM_BINARY;
}

/// An empty folder `name` (nested names allowed) of this test process's own: ctest runs every test at 1 and
/// 2 threads, possibly at once, so the root carries the pid. The root goes when the process exits, so a
/// test run leaves nothing behind in the temporary folder.
inline std::filesystem::path scratch_dir(const std::string& name) {
  namespace fs = std::filesystem;
  struct Root {
    fs::path path = fs::path(::testing::TempDir()) / ("triaxdem_test_" + std::to_string(::getpid()));
    ~Root() {
      std::error_code ignored;  // a folder a child process still holds is not worth a failure at exit
      fs::remove_all(path, ignored);
    }
  };
  static const Root root;
  const fs::path dir = root.path / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

/// The cell tests' solver: no gravity, local damping 0.7, dt a fifth of the critical step.
inline SolverConfig cell_solver() {
  SolverConfig s;
  s.gravity = {0, 0, 0};
  s.damping = 0.7;
  s.dt_safety = 0.2;
  return s;
}

/// Contact parameters in one line: E* (Pa), kn/ks, mu_s, mu_r, normal damping ratio.
inline ContactParams law(double emod, double kratio, double mu_s, double mu_r, double beta_n = 0) {
  ContactParams p;
  p.emod = emod;
  p.kratio = kratio;
  p.mu_s = mu_s;
  p.mu_r = mu_r;
  p.beta_n = beta_n;
  return p;
}

/// A cylindrical specimen of 2 mm beads (diameter = height = size, m) for the quick tests: density scaling
/// x100, no gravity, the platen at 50 mm/s.
inline Config specimen_config(double size, double void_ratio, long layers) {
  Config c;
  c.path = "<test>";
  c.has_specimen = true;
  c.specimen.diameter = size;
  c.specimen.height = size;
  c.specimen.void_ratio = void_ratio;
  c.specimen.layers = layers;
  c.specimen.platen_speed = 0.05;
  c.solver.mass_scale = 100;
  c.solver.gravity = {0, 0, 0};
  return c;
}

/// A tiny periodic cell: 100 balls sheared to 1%, a few seconds a run. 100 balls: consolidated and sheared, the
/// cell's side is about 1.19 times the 3 contact cut-offs a periodic cell needs. 64 balls (1.03) ended 0.1% short of
/// it in the sanitizer build, whose rounding differs; the config check now refuses them
/// (PeriodicCell.TooFewBallsForTheCellAreRefused).
inline Config tiny_cell_config() {
  Config cfg;
  cfg.particles.count = 100;
  cfg.particles.diameter = 2e-3;
  const Real L = std::cbrt(100 * M_PI / 6 * 8e-9 / 0.1);  // loose: insertion keeps off the seams of a small box
  cfg.box.size = {L, L, L};
  cfg.box.periodic = {true, true, true};
  cfg.solver.gravity = {0, 0, 0};
  cfg.solver.damping = 0.7;
  cfg.solver.dt_safety = 0.2;
  cfg.ball.mu_s = 0.3;
  cfg.periodic.prep_mu_s = 0;
  cfg.periodic.prep_unbalanced_tolerance = 5e-2;
  cfg.periodic.triax.consolidation_rate = 100;
  cfg.periodic.triax.target_strain = 0.01;
  cfg.periodic.triax.target_inertial = 1e-3;
  cfg.periodic.triax.record_strain = 0.001;
  return cfg;
}

/// The tiny drained triaxial test (16 mm x 16 mm, about 450 beads of 2 mm in 3 layers) of the job-level tests:
/// quick settings (inertial number 1e-2, density scaling, a coarse 24 x 8 membrane) so that a run takes seconds.
inline Config tiny_triaxial_config(double mu_s, double mu_r) {
  Config c = specimen_config(16e-3, 0.70, 3);
  c.specimen.stop_ratio = 1e-2;  // the specimen only has to be at rest enough to be sheared
  c.triaxial.sigma3 = 100e3;
  c.triaxial.stop_ratio = 1e-2;
  c.triaxial.max_consolidation_steps = 50000;
  c.triaxial.inertial_number = 1e-2;
  c.triaxial.record_every = 0.005;
  c.triaxial.membrane_around = 24;
  c.triaxial.membrane_segments = 8;
  c.micro.rve_edge = 8e-3;
  c.ball.mu_s = mu_s;
  c.ball.mu_r = mu_r;
  c.wall = c.ball;
  return c;
}

}  // namespace dem::test
