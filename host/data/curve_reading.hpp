#pragma once
/// Reading simulated and measured curves alike: values at fixed strains, the scatter of a curve's rows, the
/// mean curve of an ensemble. The misfit (host/fit/misfit.hpp) compares what these read.
#include <array>
#include <vector>

#include "host/data/measured.hpp"

namespace dem {

/// The strains at which curves are compared.
constexpr std::array<Real, 12> kFeatureStrains{2e-4, 5e-4, 1e-3, 2e-3, 5e-3, 0.01, 0.02, 0.03, 0.05, 0.075, 0.10, 0.15};

/// Half-width of the window of curve_value at strain e.
Real feature_window(Real e);

/// The value of v at strain e: a least-squares line over the rows within feature_window(e), or the straight
/// line between the rows around e when the window holds fewer than three. NaN outside the curve.
Real curve_value(const std::vector<Real>& eps_a, const std::vector<Real>& v, Real e);

/// Scatter of a curve's rows about a smooth trend (local parabolas): the standard deviation of the noise and the
/// lag-1 correlation of the rows about the trend (>= 0). NaN when the curve has fewer than kMinNoiseRows rows.
struct RowNoise {
  Real sd = 0, rho = 0;
};
constexpr int kMinNoiseRows = 20;
RowNoise row_noise(const std::vector<Real>& eps_a, const std::vector<Real>& v);

/// The straight line between the rows of eps_a around e (the first row's value at or before it).
Real interpolate(const std::vector<Real>& eps_a, const std::vector<Real>& y, Real e);

/// The mean curve of an ensemble's members (each interpolated onto the first successful member's strains),
/// summarised: what the figures and tables show for a parameter point.
TriaxialTest mean_curve(const std::vector<TriaxialTest>& members);

}  // namespace dem
