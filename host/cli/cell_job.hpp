#pragma once
/// The cell commands (`periodic`, `compression`): one chain for a test of a packed cell, periodic or between walls
/// (the plan before the packing, the packing, the cell, the test, its timings, a blow-up saved), and what each test
/// adds to it (CellTest). A new test of the cell is a CellTest and a command that runs it.
#include <string>
#include <utility>
#include <vector>

#include "host/config/config.hpp"
#include "host/engine/stage_loop.hpp"

namespace dem {

class Simulation;
struct CellCost;
namespace io {
class Output;
}

/// What a cell's test adds to the chain run_cell_job runs.
class CellTest {
 public:
  virtual ~CellTest() = default;
  /// The command, in the plan's line and the blow-up's checkpoint ("periodic", "compression").
  virtual std::string kind() const = 0;
  /// The plan's words for what follows the consolidation, and the steps the whole test takes (its consolidation
  /// included; low and high) at `cost`.
  virtual std::string plan_words() const = 0;
  virtual std::pair<long, long> steps(const CellCost& cost) const = 0;
  /// The test on the packed cell at `tp` (the config's [periodic] test, named by the run) into `out` (its record,
  /// summary or data, and its own lines): its stages' timings.
  virtual std::vector<StageTiming> run(Simulation& sim, const PeriodicTriaxialParams& tp, io::Output& out) const = 0;
  /// The files it left in `folder` said, and its plots made.
  virtual void finish(const std::string& folder) const = 0;
};

/// `test` on the cell of `cfg` ([particles], [periodic]): the config checked as the cell test checks it, the plan
/// (print_cell_plan) before the packing, the packing, the cell, the test, its time loop and timings. Returns 0, or 2
/// on a blow-up (the series so far, a snapshot and a checkpoint of the state saved in the output folder).
int run_cell_job(const Config& cfg, const CellTest& test);

}  // namespace dem
