#pragma once
/// The parameters of a material pair's contact law (contact_law.hpp). Free of Kokkos, so that the config reader,
/// which a CUDA build compiles with the host compiler (CMakeLists.txt), can fill them.
#include <cstdint>

#include "kernels/core/real.hpp"

// Device-callable where a CUDA compiler builds the file (the kernels), a plain function where the host compiler does
// (the config reader): this header is free of Kokkos and its KOKKOS_INLINE_FUNCTION.
#if defined(__CUDACC__)
#define DEM_HOST_DEVICE __host__ __device__
#else
#define DEM_HOST_DEVICE
#endif

namespace dem {

/// The contact laws a material pair may choose ([material] law), by the value of ContactParams::law; each is a
/// composition of sub-models in contact_law.hpp (ContactLaws lists them in this order). As wide as a Real, so that the
/// pair table, which its hashes read byte by byte, has no padding.
enum ContactLawId : std::int64_t { kRRLinear, kHertzMindlin, kRRLinearKr, kContactLaws };
inline constexpr const char* kContactLawNames[kContactLaws] = {"rrlinear", "hertz_mindlin", "rrlinear_kr"};

/// The type of the law field: the id for one pair; for W pairs as SIMD lanes (simd.hpp), each lane's id as a T, which
/// the lanes compare at once.
template <class T>
struct LawField {
  using type = T;
};
template <>
struct LawField<Real> {
  using type = ContactLawId;
};

/// Parameters of one material pair. Units: Pa, -, -, -, -, then as each field says. T is Real, or a pack of W pairs' values (simd.hpp).
template <class T>
struct ContactParamsT {
  typename LawField<T>::type law = kRRLinear;  ///< the pair's law
  T emod = 1e8;     ///< rrlinear: effective modulus E* of the deformability method (Pa)
  T kratio = 1.5;   ///< rrlinear: kappa* = kn / ks
  T shear_modulus = 0;  ///< hertz_mindlin: the balls' shear modulus G (Pa)
  T poisson = 0;        ///< hertz_mindlin: the balls' Poisson ratio nu
  T kr_ratio = 1;       ///< rrlinear_kr: the rolling spring's stiffness over ks Rbar^2
  T mu_s = 0.5;     ///< sliding friction coefficient
  T mu_r = 0.0;     ///< rolling friction coefficient
  T beta_n = 0.0;   ///< normal viscous damping ratio (PFC dp_nratio); 0 = off, force never tensile
  // Extensions (see the top of contact_law.hpp), 0 = off.
  T hertz_overlap = 0.0;  ///< Hertz-Mindlin: overlap / r at which the secant stiffness equals kn
  T roughness = 0.0;      ///< rough-surface compliance: combined rms roughness / r
  T wear = 0.0;           ///< slip weakening: fraction of mu_s lost after long sliding
  T wear_slip = 0.5;      ///< slip weakening: sliding distance / r over which friction decays by 1/e
  T twist = 0.0;          ///< twisting resistance: the spin moment's cap over Rbar Fn (the spin analogue of mu_r)
  T adhesion = 0.0;       ///< adhesion between touching balls: pull-off force over (2 r)^2 (Pa)

  /// Every field in one list, in order: f(this pair's field, the same field of ContactParams). The lanes' copy
  /// (law_table.hpp) goes through it, and a field missing here fails the check below: a new field is two lines of
  /// this file.
  template <class F>
  constexpr DEM_HOST_DEVICE void each_field(F&& f) {
    using P = ContactParamsT<Real>;
    f(law, &P::law);
    f(emod, &P::emod);
    f(kratio, &P::kratio);
    f(shear_modulus, &P::shear_modulus);
    f(poisson, &P::poisson);
    f(kr_ratio, &P::kr_ratio);
    f(mu_s, &P::mu_s);
    f(mu_r, &P::mu_r);
    f(beta_n, &P::beta_n);
    f(hertz_overlap, &P::hertz_overlap);
    f(roughness, &P::roughness);
    f(wear, &P::wear);
    f(wear_slip, &P::wear_slip);
    f(twist, &P::twist);
    f(adhesion, &P::adhesion);
  }

  /// The same pair without the extensions (specimen preparation, which must not depend on them).
  ContactParamsT base() const {
    ContactParamsT b = *this;
    b.hertz_overlap = b.roughness = b.wear = b.twist = b.adhesion = 0;
    return b;
  }
};
using ContactParams = ContactParamsT<Real>;

/// The fields each_field lists.
constexpr int contact_field_count() {
  ContactParams p{};
  int n = 0;
  p.each_field([&n](auto&, auto) { ++n; });
  return n;
}
static_assert(sizeof(ContactParams) == contact_field_count() * sizeof(Real) && sizeof(ContactLawId) == sizeof(Real),
              "ContactParams::each_field must list every field");

/// The scalar history the extensions keep per contact, by name (units: slip m, twist N m). Storage
/// (ContactList::slot), the rebuild's remap, the saved state and the checkpoint loop over this list, so an
/// extension's history is one line here and its use in the law.
enum HistorySlot : int { kSlipSlot, kTwistSlot, kHistorySlots };
inline constexpr const char* kHistorySlotNames[kHistorySlots] = {"slip", "twist"};

}  // namespace dem
