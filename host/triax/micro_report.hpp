#pragma once
/// The micromechanics a triaxial run records: a row of scalars with every series record
/// (coordination, strong/weak networks, anisotropy of the whole, strong and weak networks, Love-Weber
/// stress), and at the paper's points A-D the distributions (O_n, roses) and the force chains of the
/// representative volume. Column names carry units.
#include <string>
#include <vector>

#include "host/engine/micro.hpp"

namespace dem {

/// Scalars of one state. `volume`: the specimen's volume (m^3) for the Love-Weber stress.
struct MicroRow {
  Coordination z;
  Networks net;
  Anisotropy all, strong, weak;
  Tensor stress{};        ///< Love-Weber, boundary contacts included: the specimen's mean stress (Pa)
  Real q_over_p = 0;      ///< from `stress`
  Real q_over_p_sff = 0;  ///< the stress-force-fabric estimate (sff_stress_ratio)
};
MicroRow micro_row(const ContactSet& s, Real volume);

/// Every field of a row as numbers (the coordination histogram with its length first), and back: what a
/// checkpoint keeps. micro_row_from reads one row from `v` at `at` and advances it; throws std::runtime_error
/// when `v` ends early.
void append_micro_state(const MicroRow& r, std::vector<double>& v);
MicroRow micro_row_from(const std::vector<double>& v, std::size_t& at);

/// Column names and values of a row, in the same order.
std::vector<std::string> micro_columns(const std::string& prefix = "");
std::vector<double> micro_values(const MicroRow& r);

/// Writes <folder>/micro_<label>.csv files for one state: coordination distribution (n, all, strong, weak),
/// roses (theta, density, mean fn, mean ft for all, strong, weak) and force_chains_<label>.vtk of `rve`.
void write_micro_state(const std::string& folder, const std::string& label, const ContactSet& s,
                       const ContactSet& rve, int rose_bins);

/// Volume enclosed by a snapshot's membrane surface and the two platens (m^3): signed tetrahedra from the
/// axis point on the bottom platen, plus the cone over the top cap.
Real surface_volume(const io::SurfaceSnapshot& surface);

}  // namespace dem
