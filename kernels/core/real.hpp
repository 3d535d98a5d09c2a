#pragma once
/// The engine's floating-point type, apart from Kokkos (contact_params.hpp needs it without).
namespace dem {

using Real = double;  ///< SI units everywhere inside the engine

}  // namespace dem
