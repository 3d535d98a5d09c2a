#pragma once
/// What a contact law works on and how a table of laws sends a call to each pair's: a contact's kinematics, history
/// and output (for one pair, or W pairs as SIMD lanes), the parameters of lanes, and LawTable, which contact_law.hpp
/// fills with its laws (ContactLaws).
#include <cstdint>
#include <tuple>
#include <type_traits>

#include "kernels/core/contact_params.hpp"
#include "kernels/core/vec3.hpp"

namespace dem {

/// Makes a parameter non-deduced, so that a Real or an int argument converts to the law's T.
template <class T>
struct Same {
  using type = T;
};
template <class T>
using Arg = typename Same<T>::type;

/// A field of the parameters from its lanes' value: T, or the law's id for one pair. A function template of its own
/// so that the id's branch is discarded for lanes (clang checks a generic lambda's non-dependent branches).
template <class F, class T>
KOKKOS_INLINE_FUNCTION F field_of_lanes(const T& v) {
  if constexpr (std::is_enum<F>::value)
    return static_cast<F>(static_cast<std::int64_t>(v));
  else
    return v;
}

/// The parameters of W material pairs as lanes: pair(k) gives lane k's.
template <class T, class Pair>
KOKKOS_INLINE_FUNCTION ContactParamsT<T> params_of_lanes(const Pair& pair) {
  ContactParamsT<T> P;
  P.each_field([&](auto& out, auto m) {
    const T v = from_lanes<T>([&](int k) { return static_cast<Real>(pair(k).*m); });
    out = field_of_lanes<std::decay_t<decltype(out)>>(v);
  });
  return P;
}

/// Geometry and kinematics of one contact, seen from particle 1 ("i"); body 2 is a particle or a wall.
/// n points from 1 to 2; vrel is the velocity of 2 relative to 1 at the contact point; dtheta the
/// relative rotation increment (w2 - w1) dt. R2 = 0 marks a wall.
template <class T>
struct ContactKinematicsT {
  Vec3T<T> n;
  T overlap;   ///< m, > 0 when touching
  T kn;        ///< N/m, normal stiffness of this pair (Normal::stiffness, computed once per contact)
  T r1, r2;    ///< m
  T m1, m2;    ///< kg, masses (m2 = 0 at walls), for the dashpot's reduced mass
  Vec3T<T> vrel;      ///< m/s
  Vec3T<T> dtheta;    ///< rad
  Real dt;            ///< s
};
using ContactKinematics = ContactKinematicsT<Real>;

/// History carried by a contact between steps (contact-plane vectors stored in global coordinates).
template <class T>
struct ContactHistoryT {
  Vec3T<T> fs;                          ///< shear force on particle 1 (N)
  Vec3T<T> mr;                          ///< rolling moment on particle 1 (N m)
  typename LaneFlags<T>::type flags{};  ///< ContactFlag bits
  T slot[kHistorySlots] = {};           ///< the extensions' scalar history, by HistorySlot
};
using ContactHistory = ContactHistoryT<Real>;

/// What a law returns for particle 1: total force and the extra (non-lever) moment.
template <class T>
struct ContactOutputT {
  Vec3T<T> force;    ///< N, on particle 1
  Vec3T<T> moment;   ///< N m, on particle 1, excluding the lever arm of force
  T fn = 0;          ///< N, elastic normal force (dashpot excluded), >= 0
};
using ContactOutput = ContactOutputT<Real>;

/// Normal force, its tangent stiffness dFn/doverlap and the shear stiffness that goes with it (N, N/m, N/m): the
/// shear, rolling and twisting springs take ks.
template <class T>
struct NormalResponseT {
  T fn;
  T k;
  T ks;
};
using NormalResponse = NormalResponseT<Real>;

/// The largest tangent normal and shear stiffness of a contact (N/m), for the critical time step.
struct MaxStiffness {
  Real kn, ks;
};

/// One lane's choice of a or b where m holds, for every field of a contact's history or output.
template <class M, class T>
KOKKOS_INLINE_FUNCTION ContactHistoryT<T> select(const M& m, const ContactHistoryT<T>& a, const ContactHistoryT<T>& b) {
  ContactHistoryT<T> out;
  out.fs = select(m, a.fs, b.fs);
  out.mr = select(m, a.mr, b.mr);
  out.flags = select_flags(m, a.flags, b.flags);
  for (int q = 0; q < kHistorySlots; ++q) out.slot[q] = select(m, a.slot[q], b.slot[q]);
  return out;
}
template <class M, class T>
KOKKOS_INLINE_FUNCTION ContactOutputT<T> select(const M& m, const ContactOutputT<T>& a, const ContactOutputT<T>& b) {
  ContactOutputT<T> out;
  out.force = select(m, a.force, b.force);
  out.moment = select(m, a.moment, b.moment);
  out.fn = select(m, a.fn, b.fn);
  return out;
}

/// The laws a pair may choose, in ContactLawId's order: each kernel call goes to the law of the pair's `law` field.
/// Lanes of one law (nearly always) run that law alone, with its bits; lanes of two laws run both on copies of the
/// history and keep each lane's own. A new law is one `using` and one entry in ContactLaws (contact_law.hpp) and
/// one name in contact_params.hpp.
template <class... Laws>
struct LawTable {
  /// The history slots any of the laws uses with parameters p.
  template <class T>
  KOKKOS_INLINE_FUNCTION static unsigned slots(const ContactParamsT<T>& p) {
    return (Laws::slots(p) | ...);
  }
  template <class T>
  KOKKOS_INLINE_FUNCTION static T stiffness(const ContactParamsT<T>& p, const Arg<T>& r1, const Arg<T>& r2) {
    return each_law(p, [&](auto law) { return decltype(law)::stiffness(p, r1, r2); });
  }
  template <class T>
  KOKKOS_FORCEINLINE_FUNCTION static ContactOutputT<T> eval(const ContactParamsT<T>& p, const ContactKinematicsT<T>& k,
                                                           ContactHistoryT<T>& h) {
    // Every lane of one law (all but packs that straddle two laws): that law on the history itself, no copies (the
    // copies and selects below cost 14% of the force kernel's instructions when always taken).
    ContactOutputT<T> out;
    bool done = false;
    ((!done && all(is<Laws>(p.law)) ? (out = Laws::eval(p, k, h), done = true) : false), ...);
    return done ? out : eval_mixed(p, k, h);
  }
  /// For one pair (scalar parameters): a servo's spring and the critical time step's largest stiffness.
  KOKKOS_INLINE_FUNCTION static Real servo_stiffness(const ContactParams& p, Real r1, Real r2) {
    return each_law(p, [&](auto law) { return decltype(law)::NormalPart::servo_stiffness(p, r1, r2); });
  }
  KOKKOS_INLINE_FUNCTION static MaxStiffness max_stiffness(const ContactParams& p, Real r1, Real r2, Real overlap) {
    MaxStiffness m{};
    each_law(p, [&](auto law) {
      m = decltype(law)::NormalPart::max_stiffness(p, r1, r2, overlap);
      return Real(0);
    });
    return m;
  }

 private:
  /// Lanes of several laws: each law present on a copy of the history, each lane keeping its own law's.
  template <class T>
  KOKKOS_INLINE_FUNCTION static ContactOutputT<T> eval_mixed(const ContactParamsT<T>& p,
                                                             const ContactKinematicsT<T>& k, ContactHistoryT<T>& h) {
    ContactHistoryT<T> out_h = h;
    const ContactOutputT<T> out = each_law(p, [&](auto law) {
      ContactHistoryT<T> mine = h;
      const ContactOutputT<T> o = decltype(law)::eval(p, k, mine);
      const auto own = is<decltype(law)>(p.law);
      out_h = all(own) ? mine : select(own, mine, out_h);
      return o;
    });
    h = out_h;
    return out;
  }
  /// Whether a pair's law (each lane's, for lanes) is Law.
  template <class Law, class L>
  KOKKOS_INLINE_FUNCTION static auto is(const L& law) {
    return law == L(index_of<Law>());
  }
  template <class Law>
  KOKKOS_INLINE_FUNCTION static constexpr int index_of() {
    int k = 0, at = -1;
    ((at = std::is_same<Law, Laws>::value ? k : at, ++k), ...);
    return at;
  }
  /// f(Law{}) for the laws the lanes of p use, each lane's result from its own law (f returns a Real, a pack or a
  /// ContactOutput).
  template <class P, class F>
  KOKKOS_FORCEINLINE_FUNCTION static auto each_law(const P& p, const F& f) {
    using R = decltype(f(first_law()));
    R out{};
    bool set = false;
    ((!set && all(is<Laws>(p.law)) ? (out = f(Laws{}), set = true) : false), ...);
    if (set) return out;
    ((any(is<Laws>(p.law))
          ? (out = set ? select(is<Laws>(p.law), f(Laws{}), out) : f(Laws{}), set = true)
          : false),
     ...);
    return out;
  }
  static auto first_law() { return std::tuple_element_t<0, std::tuple<Laws...>>{}; }
};
}  // namespace dem
