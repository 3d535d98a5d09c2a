#pragma once
/// The two-fidelity calibration: the periodic cell drives the search, and the membrane test, the test
/// the lab ran, corrects it. At the periodic optimum both run at every pressure of the data; their difference in
/// each compared feature (the membrane test's specimens against the periodic ensemble, in the q the data report)
/// is the discrepancy the boundary makes. The periodic cell is then calibrated again against the data less that
/// discrepancy, its uncertainty counted in the misfit (Misfit::add_discrepancy), so that it reaches the
/// intervals. The discrepancy is taken as constant near the optimum; the prediction at the new optimum
/// (host/fit/prediction.hpp) shows how far that holds. Kennedy & O'Hagan (2000) call the idea autoregressive
/// co-kriging; here the correction is a measured offset per feature, not a fitted process
/// (shared/notes/triaxial_measures.md, section 4).
#include <string>
#include <vector>

#include "host/fit/misfit.hpp"
#include "host/fit/prediction.hpp"

namespace dem {

/// The membrane test's excess over the periodic cell in each feature of the misfit, with its standard error.
struct Discrepancy {
  std::vector<std::vector<Real>> delta, sd;  ///< [test][feature], the feature's unit (Pa for q)
};

/// The base config with the cell of the reference test: `cli` (--reference-test), else the base config's
/// [calibrate] reference_test; "walls" puts the cell between six walls ([periodic] boundary, host/triax/cell_boundary.hpp);
/// --reference-test periodic or two_fidelity makes it periodic; the config's own periodic or two_fidelity keep its
/// boundary.
Config reference_cell(const Config& base, const std::string& cli);

/// Whether the calibration fits two fidelities: `cli` (--reference-test), else the base config's [calibrate]
/// reference_test. Two fidelities need a membrane test to predict with (`membrane`) on at least 2 specimens;
/// ConfigError names the key before any run.
bool two_fidelity_wanted(const Config& base, const std::string& cli, bool membrane);

/// Whether a feature is a stress (q at a strain; E_ini, q_1pct, q_3pct, q_peak, q_end): the boundary scales it
/// (the bulge's area, the walls' layer), so the discrepancy is taken as a ratio; strains (eps_v, eps_a at the peak,
/// dilatancy) take it as a difference.
bool scales_with_stress(const Feature& f);

/// Per feature of `misfit`, with m and p the means over the membrane test's specimens and the periodic ensemble:
/// for a stress, the cell reads rho = p / m of the membrane test, and the datum y is corrected by
/// delta = (1 - rho) y; for a strain, delta = m - p. sd from the two sets' sample scatter s_m, s_p over K_m, K_p
/// specimens: |rho y| sqrt(s_m^2 / (K_m m^2) + s_p^2 / (K_p p^2)) or sqrt(s_m^2 / K_m + s_p^2 / K_p) (K_m, K_p >= 2;
/// a set of one gives no scatter and is refused). `membrane[k].members` and `periodic[k]` run test k of the misfit.
Discrepancy measure_discrepancy(const Misfit& misfit, const std::vector<Prediction>& membrane, const Ensemble& periodic);

/// The discrepancy in words for the report: per test, the cell's ratio to the membrane test and the correction of the
/// data's q with its sd (kPa), means over the compared stresses (E_ini left out).
std::string discrepancy_text(const Misfit& misfit, const Discrepancy& d, const std::vector<TriaxialTest>& tests);

}  // namespace dem
