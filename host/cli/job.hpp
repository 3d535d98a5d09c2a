#pragma once
/// The commands (`triaxdem <command>`), one function each, called by main: the layers below hold what they run.
#include <string>
#include <vector>

#include "host/config/config.hpp"
#include "host/engine/stage_loop.hpp"
#include "host/study/study.hpp"
#include "host/triax/specimen.hpp"

namespace dem {

/// Runs the job, writing OUT/checkpoint.h5 every [run] checkpoint_every steps or checkpoint_minutes, at a
/// SIGINT or SIGTERM and at the end. `resume`: continues from that checkpoint to [run] steps, bit for bit
/// the run that was not stopped. `stop_at_step` >= 0: stop with a checkpoint after that step. Returns 0 on
/// success, 2 on a blow-up (after saving a snapshot and the state for inspection), 128 + the signal when
/// stopped by one, 3 at stop_at_step.
int run_job(const Config& cfg, bool resume = false, long stop_at_step = -1);

/// What each stage of a job cost, stage by stage and part by part of the step: printed, and written to
/// `folder`/timings.csv (nothing where no stage ran in this process).
void report_timings(const std::string& folder, const std::vector<StageTiming>& stages);

/// What the membrane jobs do with a specimen layer that blows up: its state saved in `out`'s folder for inspection
/// (save_blowup_state, a checkpoint of kind "specimen") and said.
LayerBlowUp layer_blowup(io::Output& out, const Config& cfg);

/// `triaxdem check`: validates the config and describes the job it is for (a membrane triaxial test when it has
/// [specimen], a periodic cell when it has [periodic], else the `run` job's box): balls, geometry, stages, the time
/// step of its beads and laws, steps, and a wall-time estimate from the speed measured on a box of its beads.
int check_job(const Config& cfg);

/// Builds the [specimen] of a config by multilayer compaction and writes it (snapshot, layers.csv with
/// the void ratio of each layer, porosity_profile.csv). Returns 0 on success, 2 on a blow-up.
int specimen_job(const Config& cfg);

/// The `triaxial` CLI job: specimen, then run_triaxial with checkpoints in OUT/checkpoint.h5 ([run]
/// checkpoint_every, checkpoint_minutes, SIGINT, SIGTERM), outputs and a summary. `resume`: continue from the
/// checkpoint. Returns 0, 2 on a blow-up, 128 + the signal or 3 (stop_at_step) when stopped with a checkpoint.
int triaxial_job(const Config& cfg, bool resume = false, long stop_at_step = -1);

/// The `periodic` job: packing from [particles]/[box] (box.periodic must be all true, gravity zero),
/// optional preparatory consolidation, then run_periodic_triaxial with output in [run] output.
/// Returns 0, or 2 on a blow-up (state saved).
int run_periodic_job(const Config& cfg);

/// The `compression` job: the cell of a periodic job's config (fully periodic or [periodic] boundary = "walls"),
/// consolidated to [periodic] sigma3, then loaded in increments to `targets_kpa` (kPa; empty: 2, 4, 8, 4 and 2 times
/// sigma3) along `path` ("oedometer" or "isotropic", host/triax/compression_test.hpp), a row per increment in
/// series.csv. Returns 0, or 2 on a blow-up (state saved).
int compression_job(const Config& cfg, const std::string& path, const std::vector<double>& targets_kpa);

/// `triaxdem micro`: the micromechanics of one saved state. `source` is a run folder (then `at_pct` picks
/// the snapshot taken at that axial strain) or a snapshot file. Writes micro_<label>.csv (one row of the
/// micro columns for the specimen and the cube), the distributions and the force chains into `output`
/// and prints the headline numbers. Throws std::runtime_error with what was asked and what exists.
/// Files of an earlier micro of the same state in `output` are refused unless `overwrite`.
int micro_job(const std::string& source, double at_pct, double rve_edge_mm, int rose_bins, const std::string& output,
              bool overwrite = false);

/// Runs the study; returns 0 when every case finished, 1 otherwise (the summary then lists the failures).
/// study_summary.csv is rewritten whenever a case finishes, so a study stopped half-way leaves its table.
int study_job(const std::vector<std::string>& inputs, const StudyOptions& opt, const char* self_exe);

}  // namespace dem
