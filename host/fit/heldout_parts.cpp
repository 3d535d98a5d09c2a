// The held-out check's parts of a misfit's data (host/fit/misfit.hpp, heldout_parts).
#include <algorithm>

#include "host/fit/misfit.hpp"
#include "host/util/text_format.hpp"

namespace dem {

HeldOutParts heldout_parts(const Misfit& misfit) {
  HeldOutParts h;
  std::size_t at = 0;
  if (misfit.tests() >= 2) {
    for (std::size_t k = 0; k < misfit.tests(); ++k) {
      HeldOutPart p;
      p.test = k;
      for (std::size_t i = 0; i < misfit.features(k).size(); ++i, ++at) {
        p.local.push_back(i);
        p.global.push_back(at);
      }
      h.parts.push_back(p);
    }
    h.basis = "each pressure predicted from the others";
    return h;
  }
  std::vector<Real> strains;
  if (misfit.tests() == 1)
    for (const Feature& f : misfit.features(0))
      if (f.strain > 0) strains.push_back(f.strain);
  if (strains.size() < 2) {
    h.basis = misfit.tests() == 1 ? "one test of summary points: no part of the data can be predicted from the rest"
                                  : "no data";
    return h;
  }
  std::sort(strains.begin(), strains.end());
  const Real median = strains[(strains.size() - 1) / 2];
  HeldOutPart early, late;
  for (std::size_t i = 0; i < misfit.features(0).size(); ++i) {
    const Real strain = misfit.features(0)[i].strain;
    if (strain <= 0) continue;  // a quantity of the whole test stays in every fit
    HeldOutPart& p = strain <= median ? early : late;
    p.local.push_back(i);
    p.global.push_back(i);
  }
  if (early.local.empty() || late.local.empty()) {
    h.basis = "one test whose curve has a single strain: no part of it can be predicted from the rest";
    return h;
  }
  h.parts = {early, late};
  h.basis = "one test: its curve beyond " + fmt("%.3g", 100 * median) + "% axial strain predicted from the curve "
            "before, and the curve before from the curve beyond";
  return h;
}

}  // namespace dem
