#pragma once
/// The engine's floating-point type, apart from Kokkos (contact_params.hpp needs it without).
#include <limits>

namespace dem {

using Real = double;  ///< SI units everywhere inside the engine
/// A value not known or not there (a curve's value beyond its end, a column a file lacks).
inline constexpr Real kNaN = std::numeric_limits<Real>::quiet_NaN();

}  // namespace dem
