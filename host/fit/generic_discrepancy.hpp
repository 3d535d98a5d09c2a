#pragma once
/// Generic discrepancies: shapes with no physics, each of one parameter as an extension has, fitted beside the
/// extensions as their rivals. Real data always differ from a simulator in ways no extension is about (preparation,
/// fabric, specimen size, rate, another code's laws); an extension flexible enough to shape the curves takes such a
/// difference up and passes the verdict's tests against the base model alone (YADE's cohesionless linear data were
/// named adhesion, chi2 40.5 -> 10.3). Brynjarsdottir and O'Hagan (2014, "Learning about physical parameters: the
/// importance of model discrepancy") show that a physical parameter fitted without a discrepancy term absorbs the
/// discrepancy; Kennedy and O'Hagan (2001) model it as a function beside the simulator. The diagnosis takes their
/// idea as a test: a physical extension is named only where it explains the data better than the best generic
/// discrepancy of its own size (one parameter) by the verdict's margins, i.e. where its shape is specific.
///
/// A shape is fitted jointly with the base parameters over the base calibration's runs: at each point run whole,
/// each test's simulated curve changed by the shape at the best c, its residuals the run's plus what the change
/// makes (so c = 0 is the run itself). No simulator runs: the shapes act on what the simulator gave.
#include <string>
#include <vector>

#include "host/fit/calibrate.hpp"

namespace dem {

/// A discrepancy shape: how it changes a simulated test by c, and c's range.
struct GenericShape {
  std::string name;     ///< "q scaled"
  std::string formula;  ///< "q (1 + c)", for the report
  Real lo = 0, hi = 0;  ///< c's range: the size of a difference the diagnosis is about (a tenth to a half of q)
  void (*apply)(TriaxialTest& t, Real c) = nullptr;  ///< on the curve's rows, then summarised again
};

/// q scaled, q shifted by c sigma3, q offset by c 100 kPa at every pressure (an apparent cohesion), eps_v scaled, a
/// strain-hardening term c sigma3 eps_a.
const std::vector<GenericShape>& generic_shapes();

struct GenericFit {
  GenericShape shape;
  Real c = 0;
  std::vector<Real> values;  ///< the base parameters at the point taken (SI, free order)
  Real chi2 = 0, bic = 0, heldout = 0;
};

/// Each shape fitted with the base parameters over `base`'s whole points (see the top); BIC with d + 1 parameters on
/// `base.data` data; held-out chi2 as the diagnosis counts it: for each test, the point and c best on the others,
/// scored on it (NaN with one test).
std::vector<GenericFit> fit_generic(const CalibrationResult& base, const Misfit& misfit);

/// The rival of every extension: the fit of lowest BIC among `generic` (null where it is empty).
const GenericFit* generic_rival(const std::vector<GenericFit>& generic);

}  // namespace dem
