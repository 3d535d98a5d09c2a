/// The cell commands' chain (host/cli/cell_job.hpp): plan, packing, cell, test, timings, a blow-up saved.
#include "host/cli/cell_job.hpp"

#include <cstdio>
#include <memory>

#include "host/cli/job.hpp"
#include "host/engine/checkpoint.hpp"
#include "host/engine/setup.hpp"
#include "host/io/io_hdf5.hpp"
#include "host/lab/run_cost.hpp"
#include "host/triax/cell_boundary.hpp"
#include "host/triax/periodic_triaxial.hpp"
#include "host/util/progress.hpp"

namespace dem {

namespace {

/// A cell job's plan before its packing: `command`'s cell packed (at its preparation friction's cost,
/// packing_cost_at), consolidated to sigma3 and then `test`, which takes low_steps to high_steps (its consolidation
/// included), at the speed of `cost`'s probe; the particle-steps and the time on this machine.
void print_cell_plan(const Config& cfg, const std::string& command, const std::string& test, const CellCost& cost,
                     long low_steps, long high_steps) {
  const Real prep = cfg.periodic.prep_mu_s >= 0 ? cfg.periodic.prep_mu_s : cfg.ball.mu_s;
  const PackingCost at = packing_cost_at(prep);
  const double packing = static_cast<double>(cost.packing_steps), balls = static_cast<double>(cost.balls);
  const double step_s = 1e-9 * cost.ns_per_particle_step * balls;
  const double low = at.low * packing + static_cast<double>(low_steps),
               high = at.high * packing + static_cast<double>(high_steps);
  std::printf("%s: plan: %ld balls, a packing (preparation friction %.3g: %.3g to %.3g steps), consolidation to %.0f "
              "kPa and %s (%ld to %ld steps%s): %.2g to %.2g particle-steps, about %s to %s on this machine\n",
              command.c_str(), cost.balls, prep, at.low * packing, at.high * packing,
              cfg.periodic.triax.sigma3 / 1e3, test.c_str(), low_steps, high_steps,
              cost.resettles() ? ", the balls sliding on without friction: the consolidation settles them again" : "",
              low * balls, high * balls, format_duration(low * step_s).c_str(), format_duration(high * step_s).c_str());
}

/// The series so far written, the state saved in the output folder as a snapshot and a checkpoint of `kind`, and the
/// error with where it was saved on stderr. Returns 2, the jobs' status for a blow-up.
int cell_blowup(io::Output& out, Simulation* sim, const std::string& kind, const Config& cfg, const BlowUp& e) {
  if (sim) save_blowup_state(out, *sim, kind, cfg.fingerprint);
  std::fprintf(stderr, "\ntriaxdem: %s\n  state at the blow-up saved in %s (snapshot and %s)\n", e.what(),
               out.folder().c_str(), blowup_path(out.folder()).c_str());
  return 2;
}

}  // namespace

int run_cell_job(const Config& cfg, const CellTest& test) {
  check_periodic_config(cfg);
  const CellCost cost = measure_cell_cost(cfg);
  const auto [low, high] = test.steps(cost);
  print_cell_plan(cfg, test.kind(), test.plan_words(), cost, low, high);
  std::vector<BallSpec> balls;
  std::array<Real, 3> cell{};
  io::Output out(cfg.run.output);
  std::unique_ptr<Simulation> sim;  // the preparation's, then the test's: a blow-up in either is saved
  std::vector<StageTiming> timings;
  try {
    prepare_periodic_specimen(cfg, balls, cell, true, &sim);
    sim = make_periodic_simulation(balls, cell, cfg.ball, cfg.solver, cfg.periodic.boundary);
    const std::array<Real, 3> l = cell_lengths(*sim);
    std::printf("triaxdem: test: %zu balls in %s %.2f x %.2f x %.2f mm; critical dt %.3e s, dt %.3e s\n",
                balls.size(), cell_name(cfg.periodic.boundary), 1e3 * l[0], 1e3 * l[1], 1e3 * l[2],
                sim->critical_dt(), sim->params().integ.dt);
    if (cfg.solver.mass_scale != 1)
      std::printf("triaxdem: DENSITY SCALING x%g is on: inertia is not physical (quasi-static runs only)\n",
                  cfg.solver.mass_scale);
    PeriodicTriaxialParams tp = cfg.periodic.triax;
    tp.name = cfg.run.name;
    timings = test.run(*sim, tp, out);
  } catch (const BlowUp& e) {
    return cell_blowup(out, sim.get(), test.kind(), cfg, e);
  }
  std::printf("time loop (test): %s\n", describe(sim->times(), sim->particles().n, sim->step_count()).c_str());
  report_timings(out.folder(), timings);
  test.finish(out.folder());
  return 0;
}

}  // namespace dem
