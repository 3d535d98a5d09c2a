#pragma once
/// Diagnosis: what the calibrated base model gets wrong against measured data, which model extension
/// explains it, and by how much it helps.
///
/// 1. The base model (free: mu_s, mu_r by default) is calibrated (host/fit/calibrate.hpp).
/// 2. Each extension (Hertz-Mindlin stiffness, rough-surface compliance, slip-weakening friction, membrane
///    confinement; kernels/contact/contact_law.hpp, host/triax/periodic_triaxial.hpp) is run at the base optimum at three
///    strengths within its physical range. Its residuals are modelled as the base model's response surface
///    plus the extension's effect there, interpolated between the strengths (off, 1, 2, 3); the joint optimum
///    over the base parameters and the strength is run, the surrogate corrected by what the run shows, and
///    run once more. The fit reported is the best point run.
/// 3. Held-out prediction: for each pressure, the surrogate is fitted to the other pressures, and a run with
///    those parameters predicts it; the held-out misfit is the sum of those chi2 (runs, not surrogate values). Information criterion: BIC = chi2 + k ln n (k free
///    parameters, n data; the noise is known, so chi2 is -2 log-likelihood up to a constant).
/// 4. Verdict: each extension is accepted when it beats the base BIC by at least 6 (strong evidence: the nested
///    models' likelihood-ratio test) and lowers the held-out chi2 by at least 6 too (the same evidence on data
///    the fit did not see). An accepted extension is specific when it beats the best generic discrepancy of its
///    own size (host/fit/generic_discrepancy.hpp, lowest BIC) by the same margins on both; only a specific one is
///    named: the specific extension with the lowest BIC, with specific ones within 2 of its BIC, which these data
///    cannot tell apart. Accepted ones that are not specific are candidates, not causes: the verdict is "none",
///    and the report names the generic shape that fits as well and by how much. Otherwise "none", and the report
///    says whether the base model fits within the noise (chi2 below the 99% quantile of chi2 with n - k degrees
///    of freedom) or misses the data in a way no extension explains. A run of an extension fit at strength 0 is
///    a base run: when it beats the base calibration, it becomes the base fit.
#include <string>
#include <vector>

#include "host/fit/calibrate.hpp"
#include "host/fit/generic_discrepancy.hpp"

namespace dem {

/// Strong evidence (Kass and Raftery 1995): a drop of BIC, and of the held-out chi2, by at least 6.
constexpr Real kStrongEvidence = 6;

/// A model extension the diagnosis tries: its parameter, three strengths within a physical range, and the
/// signature it leaves in triaxial data (for the report).
struct Extension {
  std::string name;       ///< short name (ModelKey::extension: hertz, roughness, ...)
  std::string param;      ///< its free parameter (host/fit/calibrate.hpp)
  std::vector<Real> levels;
  std::string signature;
  bool from_off = true;   ///< the parameter going to 0 turns it off smoothly (not so for Hertz)
  std::string law;        ///< the contact law it extends (ModelKey::law); "" for every law
};

const std::vector<Extension>& extensions();
/// The extensions a diagnosis of `base` tries, in the order of extensions(): those of its contact law (`verbose`: says
/// which it does not try). extensions(), extension() and this: host/fit/extension_menu.cpp.
std::vector<Extension> extensions_of(const Model& base, bool verbose = false);
const Extension& extension(const std::string& name);  ///< throws std::invalid_argument naming the allowed ones

struct ExtensionFit {
  Extension ext;
  std::vector<Real> values;   ///< base free parameters, then the extension's
  Real strength = 0;          ///< the extension parameter's fitted value
  Evaluation best;            ///< best point run (its u has the base coordinates only)
  Real bic = 0, heldout = 0;  ///< BIC of the fit; held-out chi2 (runs)
  long runs = 0;
  bool accepted = false;      ///< passes both tests of the verdict (BIC and held-out, each by kStrongEvidence)
  bool specific = false;      ///< accepted, and passes both against the best generic discrepancy too
  std::string reason;         ///< why accepted or rejected, in words
};

struct Diagnosis {
  CalibrationResult base;
  Real base_bic = 0, base_heldout = 0;
  Real chi2_limit = 0;              ///< 99% quantile of chi2 with n - k degrees of freedom
  std::vector<ExtensionFit> fits;   ///< in the order of extensions()
  std::vector<GenericFit> generic;  ///< the generic discrepancies, in the order of generic_shapes()
  std::string verdict;              ///< name of the extension found, "none", or several joined by " or "
  std::string explanation;          ///< plain words
  /// What the held-out check predicted from what (heldout_parts), or why it could make none.
  std::string heldout_basis;
  std::vector<std::string> notes;   ///< what the search did beyond the plan (a better base run found late)
};


/// The verdict (see the top of the file) from the fits in `dg` (base, extensions, generic discrepancies): sets each
/// extension's accepted, specific and reason, and the verdict and explanation; n data, d base parameters.
void give_verdict(Diagnosis& dg, int n, int d);

/// Runs the diagnosis of `measured` (one material) from `base` with base parameters `free`; `joint`'s tests (compression
/// tests of the material) join every fit's residuals after the triaxial ones, the base's and each extension's, and
/// count in its data. The held-out check and the generic discrepancies hold out and shape the triaxial tests alone.
Diagnosis diagnose(PeriodicLab& lab, const Model& base, const std::vector<FreeParam>& free,
                   const std::vector<TriaxialTest>& measured, const Misfit& misfit, bool verbose,
                   const JointTerm& joint = {});

/// A hidden strength drawn from `seed`: log-uniform between the extension's lowest and highest level.
Real draw_strength(const Extension& e, unsigned seed);

/// Synthetic measured data: the simulator's tests of `truth` at `sigma3` (Pa), test j on member j of `lab` (modulo
/// its members: a lab prepares a specimen per test), with lab-like noise from `seed`:
/// a specimen-to-specimen factor on q (2% standard deviation), and on each row 0.5% of sigma3 on q and 0.02%
/// on eps_v, all scaled by `noise` (0: as precise as the simulation). Rows as the simulator records them.
std::vector<TriaxialTest> synthetic_tests(PeriodicLab& lab, const Model& truth, const std::vector<Real>& sigma3,
                                          const std::string& material, unsigned seed, Real noise = 1);

/// Synthetic data come from cells this many times larger than the simulator's, as real data come from specimens
/// larger than a calibration cell (they scatter half as much from specimen to specimen).
constexpr int kGeneratorCellFactor = 4;

/// Writes tests as a measured-data curve file (kPa, pct; eps_v, void_ratio and specimen_balls when every test has
/// them, the test labels when every test has one that is a number, and q_measure when given): CSV, or HDF5 when
/// the path ends in .h5 or .hdf5; through a temporary file and a rename.
void write_measured_curves(const std::string& path, const std::vector<TriaxialTest>& tests,
                           const std::string& comment, const std::string& q_measure = "");

}  // namespace dem
