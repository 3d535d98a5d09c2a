#pragma once
/// The simulator's finite-cell bias (Sigma_cell of host/fit/misfit.hpp): a small periodic cell does not respond as the
/// larger specimen the data come from, on average, and unlike the scatter that difference does not shrink with the
/// ensemble. A precise ensemble of small cells exposes it, and a free model extension takes it up: data from cells
/// of 4 and 16 times the simulator's balls were named wear with nothing hidden (docs/history/calibration.md). It is
/// measured once per material, at the base model, on a few cells of kCellCheckFactor times the balls, each
/// prepared as the simulator's are (to the data's void ratio, where the data give one), and counted as noise with
/// the size the measured difference extrapolates to at the data's specimen.
#include <string>
#include <vector>

#include "host/fit/misfit.hpp"
#include "host/lab/periodic_lab.hpp"

namespace dem {

/// The check cells have this many times the simulator's balls: four, the smallest step whose difference stands
/// clear of the check's own scatter (a cell of 4N scatters half as much as one of N).
constexpr int kCellCheckFactor = 4;
/// Check cells per material: their mean then scatters as one cell of N over 4, as much as the mean of 16 scatter
/// specimens, so the difference's own noise is split evenly between the two; each costs about 4 simulator runs.
constexpr int kCellCheckSpecimens = 4;
/// Halvings of the check cells' preparation friction (prep_friction_for): sqrt(prep_mu_s) to 1/32 of its range, a
/// void ratio within about 0.003 of the target (the range of 0 to 1 spans about 0.15; the nearer end is taken),
/// below the 0.01 by which specimens of one friction differ; each packing of a check cell costs about 2 runs' time.
/// The halvings start from a bracket around the lab's own matched friction (MatchPlan::around): four packings.
constexpr int kCellCheckPrepSteps = 5;
/// Packing seeds of the check cells start this far above the config's seed: neither an ensemble member (at most 64)
/// nor a data specimen (kForeignSeedOffset).
constexpr unsigned kCellCheckSeedOffset = 50000;
/// The bias is taken to fall as N^-kCellBiasExponent, as the scatter does (kSpecimenScatterExponent): the
/// difference between N and 4N then extrapolates to 2 times itself for a specimen of unlimited size. Finite-size
/// effects of a periodic cell that fall as 1/N would make that 4/3; the slower law is the cautious one.
constexpr Real kCellBiasExponent = 0.5;

/// How much of the difference between cells of N and F N balls separates a cell of N from a specimen of M balls
/// (M not finite: of unlimited size), under the power law of kCellBiasExponent.
Real cell_bias_extrapolation(Real n, Real factor, Real m);

/// The bias of one feature from its difference `diff` between the check cells' mean and the scatter specimens'
/// mean, whose own noise has variance `diff_var`: the part beyond that noise (zero when none is left), times
/// `extrapolation`, as a standard deviation.
Real cell_bias_sd(Real diff, Real diff_var, Real extrapolation);

/// Runs the check cells of `lab`'s cell at `base` on every measured test and returns the bias against `misfit`'s
/// features, which it only reads (Misfit::add_cell_bias counts it). `reference`: the scatter specimens' runs at
/// `base` on `lab`'s present cell.
CellBias measure_cell_bias(PeriodicLab& lab, const Model& base, const std::vector<TriaxialTest>& measured,
                           const Ensemble& reference, const Misfit& misfit);

/// The bias from the two ensembles at the base model: `reference` on the simulator's cell of `n` balls, `larger` on
/// cells of `factor` times them (walled cells where `walls`), each test's difference beyond their scatter
/// extrapolated to the test's specimen_balls; the note says by how much, the finding where it exceeds the data's
/// noise. measure_cell_bias runs the larger cells and calls it.
CellBias cell_bias_between(const Misfit& misfit, const std::vector<TriaxialTest>& measured, const Ensemble& reference,
                           const Ensemble& larger, Real n, Real factor, bool walls);

}  // namespace dem
