/// What a loaded data set is checked for beyond its columns (measured.hpp): tests no drained test can be, and
/// pressures the configs have.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "host/data/measured.hpp"
#include "host/util/text_format.hpp"

namespace dem {

void check_plausible(const std::string& path, const TriaxialTest& t, bool curves) {
  const std::string at = path + ": " + describe_test(t) + ": ";
  const std::string peak = curves ? "the peak of its q" : "q_peak";
  if (!(t.q_peak > 0))
    throw DataError(at + peak + " is " + fmt("%g", t.q_peak / 1e3) + " kPa: a drained test's deviator rises above "
                    "zero (compression positive; allowed: q_peak > 0): a sign flipped, or the wrong column?");
  if (t.q_peak < kMinPeakRatio * t.sigma3)
    throw DataError(at + peak + " " + fmt("%g", t.q_peak / 1e3) + " kPa is " + fmt("%g", t.q_peak / t.sigma3) +
                    " of sigma3 (allowed: at least " + fmt("%g", kMinPeakRatio) + " sigma3, a friction angle of 1.4 "
                    "deg): is sigma3 in Pa under a kPa header, or q in another unit than its column says?");
  if (curves && !t.eps_v.empty() && std::all_of(t.eps_v.begin(), t.eps_v.end(), [](Real v) { return v == 0; }))
    throw DataError(at + "eps_v is zero on every row: a volume not measured; leave the eps_v column out (allowed: a "
                    "measured volumetric strain)");
}

void check_pressures(const MeasuredData& d, const std::vector<Real>& sigma3) {
  for (const TriaxialTest& t : d.tests) {
    const bool known = std::any_of(sigma3.begin(), sigma3.end(),
                                   [&](Real s) { return std::fabs(s - t.sigma3) <= 1e-9 * std::max(s, t.sigma3); });
    if (!known) {
      std::ostringstream m;
      m << d.path << ": material " << t.material << " at sigma3 = " << t.sigma3 / 1e3
        << " kPa: no config for this pressure (configs have:";
      for (Real s : sigma3) m << " " << s / 1e3;
      m << " kPa)";
      throw DataError(m.str());
    }
  }
}

}  // namespace dem
